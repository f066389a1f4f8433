// The renderer and the detector agree: a rendered tag is found with its id, and its
// corners where the truth projects them (which also pins the +0.5 px AprilTag offset).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "corner_noise.hpp"
#include "covtrack/emulators/fiducial/tag_image_formation.hpp"
#include "covtrack/emulators/fiducial/tag_renderer.hpp"
#include "covtrack/protocol/camera_opencv.hpp"
#include "fiducial_scene.hpp"
#include "lens_edge_bend.hpp"
#include "tag_detector.hpp"

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
  const Camera cam = test::small_camera();
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

// The edge-shift inputs of the corner model (corner_noise.hpp), on rendered tags.
TEST(FiducialRenderDetect, BorderInnerWhiteReadsTheCodeAlongEachEdge) {
  auto f = TagFamily::open("tag36h11");
  ASSERT_TRUE(f.has_value());
  int ordered = 0;  // ids whose edge 1 has a white cell at one end and a black one at the other
  for (int id = 0; id < 60; ++id) {
    const cv::Mat cells = *(*f)->cells(id);
    const auto white = (*f)->border_inner_white(id);
    // Edge 1 (right, bottom to top) is lined by column 7 of the 10 x 10 cells, rows 7..2.
    double mean = 0;
    for (int row = 2; row <= 7; ++row) mean += (cells.at<std::uint8_t>(row, 7) > 127) / 8.0;
    EXPECT_NEAR((white[1][0] + white[1][1]) / 2, mean, 1e-12) << "id " << id;
    // The line's end nearer the white cells is the whiter one.
    const double bottom = cells.at<std::uint8_t>(7, 7) > 127, top = cells.at<std::uint8_t>(2, 7) > 127;
    if (bottom > top) {
      EXPECT_GT(white[1][0], white[1][1]) << "id " << id;
      ++ordered;
    } else if (top > bottom) {
      EXPECT_LT(white[1][0], white[1][1]) << "id " << id;
      ++ordered;
    }
  }
  EXPECT_GT(ordered, 10);
  auto reversed = TagFamily::open("tagStandard41h12");
  ASSERT_TRUE(reversed.has_value());
  for (const auto& ends : (*reversed)->border_inner_white(3)) EXPECT_EQ(ends[0] + ends[1], 0.0);
}

TEST(FiducialRenderDetect, EdgeBlurGrowsWithTheRenderedBlur) {
  const Camera cam = test::small_camera();
  auto detector = TagDetector::create(DetectorOptions{.decimate = 1});
  ASSERT_TRUE(detector.has_value());
  const RenderedTag tag{3, 0.15, test::tag_pose(0.8, 20, 10, 5)};
  std::mt19937_64 rng(3);
  double previous = 0;
  for (double blur : {0.5, 0.8, 1.1, 1.5}) {
    RenderLook look;
    look.blur_sigma_px = blur;
    const cv::Mat frame = add_sensor_noise(render_tags(cam, (*detector)->family(), {tag}, look), 2, rng);
    const auto found = (*detector)->detect(frame);
    ASSERT_EQ(found.size(), 1u) << "blur " << blur;
    const double measured =
        edge_blur_px(frame, found[0].corners_px, tag_contrast(frame, found[0].corners_px, 8));
    // The pixel's area and the interpolation add about 0.4 px in quadrature.
    EXPECT_NEAR(measured, std::hypot(blur, 0.4), 0.15) << "blur " << blur;
    EXPECT_GT(measured, previous) << "blur " << blur;
    previous = measured;
  }
}

// The three rasterisers of the image formation are independent ways of drawing a tag
// (texture warped onto a finer grid, exact covered area per pixel, random points per pixel
// looked up through the inverse homography): on a sharp, noise-free, linear image they must
// give the same picture up to their sampling, and the same corners to a few hundredths of a
// pixel.
TEST(FiducialRenderDetect, EveryRasteriserDrawsTheSameTag) {
  const Camera cam = test::camera(640, 480, 62);
  DetectorOptions opts;
  opts.decimate = 1;
  auto detector = TagDetector::create(opts);
  ASSERT_TRUE(detector.has_value());
  const RenderedTag tag{5, 0.12, test::tag_pose(0.7, 25, 10, 33, 0.03, -0.02)};
  ImageFormation f;
  f.read_noise = 0, f.gauss_blur_px = 0.7, f.jitter_seed = 9;
  const Rasteriser rasterisers[] = {Rasteriser::AnalyticArea, Rasteriser::Supersampled, Rasteriser::JitteredPoints};
  std::array<cv::Mat, 3> radiance;
  std::array<std::vector<Detection>, 3> found;
  for (std::size_t i = 0; i < 3; ++i) {
    f.rasteriser = rasterisers[i];
    radiance[i] = tag_radiance(cam, (*detector)->family(), {tag}, f);
    std::mt19937_64 rng(3);
    found[i] = (*detector)->detect(form_image(cam, (*detector)->family(), {tag}, f, rng));
    ASSERT_EQ(found[i].size(), 1u);
  }
  for (std::size_t i = 1; i < 3; ++i) {
    cv::Mat difference;
    cv::absdiff(radiance[0], radiance[i], difference);
    // Only pixels on an edge differ, by the sampling: a small share of one level.
    EXPECT_LT(cv::mean(difference)[0], 0.002) << "rasteriser " << i;
    EXPECT_GT(cv::mean(difference)[0], 0.0) << "rasteriser " << i << " is the exact area's own";
    double worst = 0;
    for (std::size_t k = 0; k < 4; ++k)
      worst = std::max(worst, cv::norm(found[0][0].corners_px[k] - found[i][0].corners_px[k]));
    // The random points' coverage errors (up to 0.017 of the contrast on this tag's edge
    // pixels) move AprilTag's corners by up to 0.03 px; the corners' own errors against
    // the truth are 0.02-0.06 px for all three.
    EXPECT_LT(worst, i == 1 ? 0.03 : 0.05) << "corners of rasteriser " << i << " differ from the exact area's";
  }
}

// A fill factor under 100%: the exact-area rasteriser integrates the pixel's sensitive
// square only, as the random points do, and so agrees with them, not with itself at 100%.
TEST(FiducialRenderDetect, ExactAreaAndRandomPointsAgreeOnAPartialFillFactor) {
  const Camera cam = test::camera(640, 480, 62);
  auto family = TagFamily::open("tag36h11");
  ASSERT_TRUE(family.has_value());
  const RenderedTag tag{5, 0.12, test::tag_pose(0.7, 25, 10, 33, 0.03, -0.02)};
  ImageFormation f;
  f.jitter_seed = 9, f.pixel_aperture = 0.7;
  f.rasteriser = Rasteriser::AnalyticArea;
  const cv::Mat exact = tag_radiance(cam, **family, {tag}, f);
  f.rasteriser = Rasteriser::JitteredPoints;
  const cv::Mat points = tag_radiance(cam, **family, {tag}, f);
  f.rasteriser = Rasteriser::AnalyticArea, f.pixel_aperture = 1;
  const cv::Mat whole = tag_radiance(cam, **family, {tag}, f);
  cv::Mat to_points, to_whole;
  cv::absdiff(exact, points, to_points);
  cv::absdiff(exact, whole, to_whole);
  std::printf("mean |exact - points| %.5f, |exact - exact at 100%%| %.5f\n", cv::mean(to_points)[0],
              cv::mean(to_whole)[0]);
  EXPECT_LT(cv::mean(to_points)[0], 0.002);
  EXPECT_GT(cv::mean(to_whole)[0], 3 * cv::mean(to_points)[0]);
  // Away from the edges nothing changes: the paper, the ink and the background are flat.
  double flat_max = 0;
  cv::minMaxLoc(to_whole(cv::Rect(0, 0, 40, 40)), nullptr, &flat_max);
  EXPECT_EQ(flat_max, 0.0);
}

// Through a lens every rasteriser still gives each pixel the mean over its footprint: the
// random points look each point up through the lens, the other two resample a pinhole
// rendering four times finer. The corners land where the lens puts them, less the bend
// of AprilTag's straight edge fit. (Resampling the pinhole image at the pixels' own scale
// instead, as the renderer once did, blurs each edge by its sub-pixel phase: on this tag
// the exact area's radiance then differs from the random points' by 0.0041 on average
// (0.00015 without the lens), the supersampling's by 0.0057 (0.0026 without).)
TEST(FiducialRenderDetect, ThroughALensEveryRasteriserDrawsTheSameTag) {
  Camera cam = test::camera(1280, 720, 70);
  cam.k1 = -0.08, cam.k2 = 0.02;
  DetectorOptions opts;
  opts.decimate = 1;
  auto detector = TagDetector::create(opts);
  ASSERT_TRUE(detector.has_value());
  const RenderedTag tag{5, 0.12, test::tag_pose(0.7, 25, 10, 33, 0.2, 0.12)};
  ImageFormation f;
  f.read_noise = 0, f.gauss_blur_px = 0.7, f.jitter_seed = 9;
  f.true_distortion = distortion_vector(cam);
  std::vector<cv::Point3d> rays;
  for (const auto& p : projected_corners(cam, tag)) rays.emplace_back((p.x - cam.cx) / cam.fx, (p.y - cam.cy) / cam.fy, 1);
  std::vector<cv::Point2d> lens_corners;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(cam), f.true_distortion, lens_corners);
  const Rasteriser rasterisers[] = {Rasteriser::AnalyticArea, Rasteriser::Supersampled, Rasteriser::JitteredPoints};
  std::array<cv::Mat, 3> radiance;
  for (std::size_t i = 0; i < 3; ++i) {
    f.rasteriser = rasterisers[i];
    radiance[i] = tag_radiance(cam, (*detector)->family(), {tag}, f);
    std::mt19937_64 rng(3);
    const auto found = (*detector)->detect(form_image(cam, (*detector)->family(), {tag}, f, rng));
    ASSERT_EQ(found.size(), 1u) << "rasteriser " << i;
    const auto bend = straight_fit_corner_offsets(cam, found[0].corners_px);
    double worst = 0, bent = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      worst = std::max(worst, cv::norm(found[0].corners_px[k] - bend[k] - lens_corners[k]));
      bent = std::max(bent, cv::norm(bend[k]));
    }
    std::printf("rasteriser %zu: corners at most %.3f px off the lens's (the bend taken off: up to %.3f px)\n", i,
                worst, bent);
    EXPECT_LT(worst, 0.08) << "rasteriser " << i << ": the corners are not where the lens puts them";
  }
  // Each rasteriser through the lens against the random points through it, over the tag
  // and 4 px around: no further apart than the two are without the lens (to 0.0005).
  cv::Rect around(cvFloor(lens_corners[0].x), cvFloor(lens_corners[0].y), 1, 1);
  for (const auto& p : lens_corners) around |= cv::Rect(cvFloor(p.x) - 4, cvFloor(p.y) - 4, 9, 9);
  const auto mean_difference = [&](const cv::Mat& a, const cv::Mat& b) {
    cv::Mat difference;
    cv::absdiff(a(around), b(around), difference);
    return cv::mean(difference)[0];
  };
  ImageFormation pinhole = f;
  pinhole.true_distortion = cv::Mat();
  pinhole.rasteriser = Rasteriser::JitteredPoints;
  const cv::Mat pinhole_points = tag_radiance(cam, (*detector)->family(), {tag}, pinhole);
  for (std::size_t i = 0; i < 2; ++i) {
    pinhole.rasteriser = rasterisers[i];
    const double without = mean_difference(tag_radiance(cam, (*detector)->family(), {tag}, pinhole), pinhole_points);
    const double through = mean_difference(radiance[i], radiance[2]);
    std::printf("rasteriser %zu against the random points: mean difference %.5f through the lens, %.5f without\n", i,
                through, without);
    EXPECT_LT(through, without + 0.0005) << "rasteriser " << i << " through the lens";
  }
}
