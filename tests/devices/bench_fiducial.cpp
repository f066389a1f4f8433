// Benchmark, run by hand: per 640x480 frame, AprilTag detection vs pose vs covariance
// (corner noise inputs + Jacobian + (J^T Sigma_c^-1 J)^-1), at decimation 1 and 2.
// The covariance's cost is printed as a share of the detection measured in the same run.
#include <chrono>
#include <cstdio>
#include <random>

#include "covtrack/devices/fiducial/corner_noise.hpp"
#include "covtrack/devices/fiducial/tag_detector.hpp"
#include "covtrack/devices/fiducial/tag_pose.hpp"
#include "covtrack/devices/fiducial/tag_renderer.hpp"
#include "fiducial_scene.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
using Clock = std::chrono::steady_clock;

int main() {
  CameraModel cam;
  cam.width_px = 640, cam.height_px = 480, cam.fx = cam.fy = 554, cam.cx = 319.5, cam.cy = 239.5;
  auto family = TagFamily::open("tag36h11");
  const std::vector<RenderedTag> tags = {{0, 0.16, test::tag_pose(1.2, 20, 5, 10, -0.15, 0)},
                                         {7, 0.08, test::tag_pose(0.9, -30, -5, -20, 0.2, 0.05)}};
  std::mt19937_64 rng(1);
  const cv::Mat frame = add_sensor_noise(render_tags(cam, **family, tags, RenderLook{}), 3, rng);
  // The calibrated coefficients (config defaults), edge-shift correction included.
  const CornerNoiseModel model = test::calibrated_corner_model();
  constexpr int kFrames = 40;
  for (double decimate : {1.0, 2.0}) {
    DetectorOptions o;
    o.decimate = decimate;
    auto detector = TagDetector::create(o);
    double detect_s = 0, pose_s = 0, cov_s = 0;
    int tags_found = 0;
    for (int f = 0; f < kFrames; ++f) {
      const auto t0 = Clock::now();
      const auto found = (*detector)->detect(frame);
      const auto t1 = Clock::now();
      // The covariance's own work: the model's inputs (noise, contrast, edge blur, border
      // widths, ...), the edge-shift correction, Jacobian, 8x8 corner covariance and the
      // information inverse.
      const double noise = estimate_image_noise(frame);
      for (const Detection& d : found) {
        const CornerNoise n = model.noise(measure_corner_inputs(frame, d, **family, noise));
        const auto moved = move_edges_in(d.corners_px, n.edge_shift_px);
        Eigen::Matrix<double, 8, 8> corner_cov = Eigen::Matrix<double, 8, 8>::Zero();
        for (int i = 0; i < 8; ++i) {
          const double extra = n.extra_px[static_cast<std::size_t>(i / 2)];
          corner_cov(i, i) = n.sigma_px * n.sigma_px + extra * extra;
        }
        volatile double sink =
            pose_covariance(corner_jacobian(cam, tags[0].T_camera_tag, 0.16), corner_cov)(0, 0) +
            moved[0].x;
        (void)sink;
      }
      const auto t2 = Clock::now();
      for (const Detection& d : found) {
        auto p = estimate_tag_pose(cam, d.corners_px, 0.1, CornerNoise{0.05, 0, 0});
        tags_found += p.has_value();
      }
      const auto t3 = Clock::now();
      detect_s += std::chrono::duration<double>(t1 - t0).count();
      cov_s += std::chrono::duration<double>(t2 - t1).count();
      pose_s += std::chrono::duration<double>(t3 - t2).count();
    }
    std::printf("decimate %.0f: detection %.2f ms/frame, pose (both IPPE solutions + LM + covariance) "
                "%.3f ms, covariance %.3f ms = %.2f%% of detection (%d tags/frame)\n",
                decimate, detect_s / kFrames * 1e3, pose_s / kFrames * 1e3, cov_s / kFrames * 1e3,
                100 * cov_s / detect_s, tags_found / kFrames);
  }
}
