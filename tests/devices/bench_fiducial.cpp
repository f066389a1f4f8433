// Benchmark, run by hand: per frame at 640x480 and 1920x1080, one tag and a 12-tag board,
// AprilTag detection vs the whole pose (both IPPE solutions, LM, covariance, ambiguity)
// vs the covariance's own work (the corner model's inputs measured from the frame, the
// lens-bend offsets, the 8x8 corner covariance, the Jacobian and (J^T Sigma_c^-1 J)^-1).
// The covariance is printed as a share of the detection measured in the same run; for the
// board, also the bundle pose of its 12 tags from their poses (joint fit, ambiguity and
// agreement checks: bundle_pose.hpp).
#include <chrono>
#include <cstdio>
#include <random>

#include "bundle_pose.hpp"
#include "corner_noise.hpp"
#include "covtrack/emulators/fiducial/tag_image_formation.hpp"
#include "fiducial_scene.hpp"
#include "lens_edge_bend.hpp"
#include "tag_detector.hpp"
#include "tag_pose.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
using Clock = std::chrono::steady_clock;

namespace {

// The 12 tags of a board, 0.08 m apart, as a bundle's config lists them.
std::vector<BundleTag> board_layout() {
  std::vector<BundleTag> tags;
  for (int id = 0; id < 12; ++id) {
    Pose T = Pose::Identity();
    T.translation() = Vec3((id % 4 - 1.5) * 0.08, (id / 4 - 1.0) * 0.08, 0);
    tags.push_back({id, 0.05, T});
  }
  return tags;
}

std::vector<RenderedTag> board(double distance_m) {
  std::vector<RenderedTag> tags;
  const Pose T_camera_board = test::tag_pose(distance_m, 20, 8, 10);
  for (const BundleTag& t : board_layout()) tags.push_back({t.id, t.size_m, T_camera_board * t.T_bundle_tag});
  return tags;
}

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

}  // namespace

int main() {
  auto family = TagFamily::open("tag36h11");
  const CornerNoiseModel model;
  constexpr int kFrames = 30;
  std::printf("%-10s %-6s %5s %12s %10s %14s %9s %10s\n", "frame", "scene", "tags", "detect ms", "pose ms",
              "covariance ms", "cov/det", "bundle ms");
  for (const auto& [width, height, decimate] : {std::tuple{640, 480, 1.0}, std::tuple{1920, 1080, 2.0}}) {
    Camera cam = test::camera(width, height, 70);
    cam.k1 = -0.1, cam.k2 = 0.03;
    for (const bool twelve : {false, true}) {
      const auto tags = twelve ? board(0.7) : std::vector<RenderedTag>{{0, 0.16, test::tag_pose(1.0, 20, 5, 10)}};
      std::mt19937_64 rng(1);
      ImageFormation f;
      f.true_distortion = distortion_vector(cam);
      f.read_noise = 3;
      const cv::Mat frame = form_image(cam, **family, tags, f, rng);
      DetectorOptions o;
      o.decimate = decimate;
      auto detector = TagDetector::create(o);
      double detect_s = 0, pose_s = 0, cov_s = 0, bundle_s = 0;
      std::size_t found_n = 0;
      for (int n = 0; n < kFrames; ++n) {
        const auto t0 = Clock::now();
        const auto found = (*detector)->detect(frame);
        const auto t1 = Clock::now();
        const double noise = estimate_image_noise(frame);
        for (const Detection& d : found) {
          const CornerNoise cn = model.noise(measure_corner_inputs(frame, d, **family, noise));
          const auto bend = straight_fit_corner_offsets(cam, d.corners_px);
          const Mat6 cov = pose_covariance(corner_jacobian(cam, tags[0].T_camera_tag, 0.05),
                                           corner_covariance(d.corners_px, cn));
          volatile double sink = cov(0, 0) + bend[0].x;
          (void)sink;
        }
        const auto t2 = Clock::now();
        std::vector<BundleObservation> seen;
        for (const Detection& d : found) {
          const CornerNoise cn = model.noise(measure_corner_inputs(frame, d, **family, noise));
          const auto pose = estimate_tag_pose(cam, d.corners_px, 0.05, cn);
          if (pose && twelve) seen.push_back({board_layout()[static_cast<std::size_t>(d.id)], *pose});
        }
        const auto t3 = Clock::now();
        if (!seen.empty()) {
          volatile bool ok = estimate_bundle_pose(cam, seen).has_value();
          (void)ok;
        }
        const auto t4 = Clock::now();
        detect_s += seconds(t0, t1), cov_s += seconds(t1, t2), pose_s += seconds(t2, t3), bundle_s += seconds(t3, t4);
        found_n = found.size();
      }
      std::printf("%4dx%-5d %-6s %5zu %12.2f %10.3f %14.3f %8.2f%% %10.3f\n", width, height,
                  twelve ? "board" : "1 tag", found_n, detect_s / kFrames * 1e3, pose_s / kFrames * 1e3,
                  cov_s / kFrames * 1e3, 100 * cov_s / detect_s, bundle_s / kFrames * 1e3);
    }
  }
}
