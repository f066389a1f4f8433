// The renderer and the detector agree: a rendered tag is found with its id, and its
// corners where the truth projects them (which also pins the +0.5 px AprilTag offset).
#include <gtest/gtest.h>

#include <random>

#include "covtrack/devices/fiducial/tag_detector.hpp"
#include "covtrack/devices/fiducial/tag_renderer.hpp"
#include "fiducial_scene.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;

namespace {

struct CornerErrors {
  int found = 0;
  cv::Point2d mean{0, 0};
  double rms = 0;
};

CornerErrors corner_errors(const std::string& family, int id, const Pose& pose, double size_m,
                           double noise, int draws) {
  const CameraModel cam = test::small_camera();
  DetectorOptions opts;
  opts.family = family;
  opts.decimate = 1;
  auto detector = TagDetector::create(opts);
  EXPECT_TRUE(detector.has_value());
  const RenderedTag tag{id, size_m, pose};
  const cv::Mat clean = render_tags(cam, (*detector)->family(), {tag}, RenderLook{});
  const auto truth = projected_corners(cam, tag);
  std::mt19937_64 rng(7);
  CornerErrors e;
  double sq = 0;
  for (int d = 0; d < draws; ++d) {
    for (const Detection& det : (*detector)->detect(add_sensor_noise(clean, noise, rng))) {
      if (det.id != id) continue;
      ++e.found;
      for (int k = 0; k < 4; ++k) {
        const cv::Point2d err = det.corners_px[k] - truth[k];
        e.mean += err / 4.0;
        sq += err.dot(err) / 4.0;
      }
    }
  }
  if (e.found) e.mean /= e.found, e.rms = std::sqrt(sq / e.found / 2);
  return e;
}

}  // namespace

TEST(FiducialRenderDetect, Tag36h11CornersLandOnTheTruth) {
  const auto e = corner_errors("tag36h11", 3, test::tag_pose(0.6, 20, 10, 5), 0.1, 2.0, 20);
  EXPECT_EQ(e.found, 20);
  // Without the 0.5 px correction the mean error would be about (0.5, 0.5).
  EXPECT_LT(std::abs(e.mean.x), 0.08) << e.mean;
  EXPECT_LT(std::abs(e.mean.y), 0.08) << e.mean;
  EXPECT_LT(e.rms, 0.25);
}

TEST(FiducialRenderDetect, EveryFamilyIsRenderedFromItsOwnCodes) {
  for (const std::string family : {"tag36h11", "tag25h9", "tag16h5", "tagStandard41h12",
                                   "tagStandard52h13", "tagCircle21h7", "tagCustom48h12"}) {
    const auto e = corner_errors(family, 5, test::tag_pose(0.5, 15, -10, 30), 0.12, 1.0, 3);
    EXPECT_EQ(e.found, 3) << family;
    EXPECT_LT(e.rms, 0.3) << family;
  }
}

TEST(FiducialRenderDetect, UnknownFamilyAndIdAreErrors) {
  EXPECT_FALSE(TagFamily::open("tag99h1").has_value());
  auto f = TagFamily::open("tag16h5");
  ASSERT_TRUE(f.has_value());
  EXPECT_FALSE((*f)->cells(100000).has_value());
}
