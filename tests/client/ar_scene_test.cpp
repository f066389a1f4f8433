// The OpenSceneGraph adapter drawn for real: Mesa's software OpenGL in a pbuffer on a
// virtual X server (the test runs under xvfb-run), read back by pixels.
//  - The matrices: OpenGL puts a point where the camera model does (no GL needed).
//  - A box drawn where it truly is, with the regions of an estimate drawn from its
//    covariance: its silhouette lies inside the 99% outer region in almost every draw,
//    and not when the covariance the regions were computed from is 100x too small.
//  - The inner region lies on the box; the outer region is drawn where it is.
//  - The Level-of-Error switch shows the level's own subgraph; the video frame fills the
//    background; a label is drawn in its box.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <osg/ShapeDrawable>

#include "covtrack/client/regions.hpp"
#include "covtrack/osg/ar_scene.hpp"
#include "covtrack/osg/ar_viewer.hpp"
#include "covtrack/osg/camera_matrices.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

Camera test_camera() {
  Camera c;
  c.width_px = 320, c.height_px = 240;
  c.fx = 300, c.fy = 310, c.cx = 161.3, c.cy = 118.2;
  return c;
}

// The box of the tests: 8 x 6 x 4 cm about its own origin.
const Vec3 kBoxSize(0.08, 0.06, 0.04);

std::vector<Vec3> box_vertices() {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1 ? 0.5 : -0.5) * kBoxSize.x(), (i & 2 ? 0.5 : -0.5) * kBoxSize.y(),
                   (i & 4 ? 0.5 : -0.5) * kBoxSize.z());
  return v;
}

// A flat-coloured box (no lighting, so every pixel of it has exactly this colour).
osg::ref_ptr<osg::Node> coloured_box(const osg::Vec4& colour) {
  osg::ref_ptr<osg::ShapeDrawable> shape =
      new osg::ShapeDrawable(new osg::Box(osg::Vec3(), float(kBoxSize.x()), float(kBoxSize.y()), float(kBoxSize.z())));
  shape->setColor(colour);
  osg::ref_ptr<osg::Geode> geode = new osg::Geode;
  geode->addDrawable(shape);
  geode->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
  return geode;
}

// The scene drawn off screen, each frame read back as RGB (top row first).
class OffscreenView {
 public:
  explicit OffscreenView(ar::ArScene& scene) {
    auto viewer = ar::ArViewer::open(scene, ar::ArViewer::Output::offscreen);
    if (viewer) viewer_ = std::move(*viewer);
    else error_ = viewer.error().message;
  }
  bool usable() const { return viewer_ != nullptr; }
  const std::string& error() const { return error_; }

  cv::Mat render() {
    viewer_->frame();
    cv::Mat rgb;
    cv::cvtColor(viewer_->image(), rgb, cv::COLOR_BGR2RGB);
    return rgb;
  }

 private:
  std::unique_ptr<ar::ArViewer> viewer_;
  std::string error_;
};

bool is_red(const cv::Vec3b& p) { return p[0] > 200 && p[1] < 60 && p[2] < 60; }
bool is_green(const cv::Vec3b& p) { return p[1] > 200 && p[0] < 60 && p[2] < 60; }

// Every red pixel's centre inside `outer` (1 px for rasterisation); how many red pixels.
bool silhouette_inside(const cv::Mat& frame, const Polygon& outer, int* red = nullptr) {
  int count = 0;
  bool inside = true;
  for (int v = 0; v < frame.rows; ++v)
    for (int u = 0; u < frame.cols; ++u)
      if (is_red(frame.at<cv::Vec3b>(v, u))) {
        ++count;
        inside = inside && polygon_contains(outer, Vec2(u, v), 1.0);
      }
  if (red) *red = count;
  return inside;
}

Pose box_pose() {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(0.5, Vec3(0.3, 1, 0.2).normalized())).toRotationMatrix();
  T.translation() = Vec3(0.02, -0.01, 0.45);
  return T;
}

Mat6 box_covariance() {
  Vec6 sigma;
  sigma << 0.004, 0.004, 0.008, 1.5 * M_PI / 180, 1.5 * M_PI / 180, 2.5 * M_PI / 180;
  Mat6 C = sigma.cwiseProduct(sigma).asDiagonal();
  C(0, 4) = C(4, 0) = 0.5 * sigma(0) * sigma(4);  // a correlated sideways shift and turn
  return C;
}

// One frame: the box drawn at `truth`, the regions of the estimate `T_est` with covariance C.
ArObjectFrame frame_of(const Camera& camera, const Pose& truth, const Pose& T_est, const Mat6& C, int level = 0) {
  ObjectRegionOptions options;
  options.regions.confidence = 0.99;
  const auto vertices = box_vertices();
  ArObjectFrame o;
  o.T_camera_object = UncertainPose{truth, C, false};
  o.regions = compute_object_regions(camera, UncertainPose{T_est, C, false}, vertices, options);
  o.level = level;
  return o;
}

ar::ArScene box_scene(ar::ArSceneOptions options = {}) {
  ar::ArScene scene(test_camera(), options);
  scene.add_object({coloured_box(osg::Vec4(1, 0, 0, 1)), coloured_box(osg::Vec4(0, 1, 0, 1))});
  return scene;
}

}  // namespace

TEST(ArSceneMatrices, OpenGlPutsAPointWhereTheCameraModelDoes) {
  const Camera c = test_camera();
  const osg::Matrixd view_projection = ar::opencv_to_eye() * ar::projection_of(c, 0.1, 10);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    const Vec3 p(0.4 * u(rng), 0.3 * u(rng), 1.5 + u(rng));
    const Vec2 pixel = c.project(p);
    const osg::Vec4d clip = osg::Vec4d(p.x(), p.y(), p.z(), 1) * view_projection;
    const double x_window = (clip.x() / clip.w() + 1) / 2 * c.width_px;
    const double y_window = (clip.y() / clip.w() + 1) / 2 * c.height_px;  // from the bottom
    EXPECT_NEAR(x_window, pixel.x() + 0.5, 1e-9);
    EXPECT_NEAR(y_window, c.height_px - pixel.y() - 0.5, 1e-9);
    EXPECT_GT(clip.z() / clip.w(), -1);
    EXPECT_LT(clip.z() / clip.w(), 1);
  }
  // A pose maps points as Pose does.
  const Pose T = box_pose();
  const Vec3 X(0.1, -0.2, 0.3), Y = T * X;
  const osg::Vec3d Z = osg::Vec3d(X.x(), X.y(), X.z()) * ar::osg_matrix(T);
  EXPECT_NEAR((Vec3(Z.x(), Z.y(), Z.z()) - Y).norm(), 0, 1e-12);
}

TEST(ArScene, TheBoxWhereItTrulyIsLiesInsideTheOuterRegionOfTheEstimate) {
  ar::ArSceneOptions options;
  options.draw_regions = false;  // the regions' own lines would hide the pixels judged
  ar::ArScene scene = box_scene(options);
  OffscreenView view(scene);
  ASSERT_TRUE(view.usable()) << view.error();
  const Camera& camera = scene.camera();
  const Pose T_est = box_pose();
  const Mat6 C = box_covariance();
  const Eigen::Matrix<double, 6, 6> L = C.llt().matrixL();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  constexpr int kDraws = 40;
  int inside = 0, inside_overconfident = 0, red_total = 0;
  for (int i = 0; i < kDraws; ++i) {
    Vec6 z;
    for (int k = 0; k < 6; ++k) z(k) = gauss(rng);
    const Pose truth = boxplus(T_est, L * z);  // T_true = T_est Exp(xi), xi ~ N(0, C)
    ArFrame frame;
    frame.objects.push_back(frame_of(camera, truth, T_est, C));
    scene.update(frame);
    const cv::Mat image = view.render();
    int red = 0;
    inside += silhouette_inside(image, frame.objects[0].regions.outer, &red);
    red_total += red;
    // The same truth judged against regions 100x too confident.
    const Polygon narrow = frame_of(camera, truth, T_est, C / 100).regions.outer;
    inside_overconfident += silhouette_inside(image, narrow);
  }
  std::printf("box silhouette inside the 99%% outer region in %d of %d draws (%.0f red pixels each); with a "
              "covariance 100x too small: %d\n",
              inside, kDraws, double(red_total) / kDraws, inside_overconfident);
  EXPECT_GT(red_total / kDraws, 1000) << "the box must be drawn, and large";
  EXPECT_GE(inside, kDraws - 3);
  EXPECT_LE(inside_overconfident, kDraws / 2) << "the test must be able to fail";
}

TEST(ArScene, InnerRegionIsOnTheBoxAndTheOuterRegionIsDrawnWhereItIs) {
  ar::ArScene scene = box_scene();
  OffscreenView view(scene);
  ASSERT_TRUE(view.usable()) << view.error();
  const Camera& camera = scene.camera();
  ArFrame frame;
  frame.objects.push_back(frame_of(camera, box_pose(), box_pose(), box_covariance() / 4));
  const ObjectRegions& regions = frame.objects[0].regions;
  ASSERT_GE(regions.inner.size(), 3u);
  scene.update(frame);
  const cv::Mat image = view.render();
  // Inside the inner region, 3 px clear of its outline: only the box.
  int judged = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u)
      if (polygon_contains(regions.inner, Vec2(u, v), -3.0)) {
        ++judged;
        EXPECT_TRUE(is_red(image.at<cv::Vec3b>(v, u))) << u << ", " << v;
      }
  EXPECT_GT(judged, 200);
  // The outer region's outline in its colour (RGB 255, 204, 0) within a pixel of each
  // edge's middle.
  const auto near_outline = [&](const Vec2& p) {
    for (int dv = -1; dv <= 1; ++dv)
      for (int du = -1; du <= 1; ++du) {
        const int u = int(std::lround(p.x())) + du, v = int(std::lround(p.y())) + dv;
        if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) continue;
        const cv::Vec3b c = image.at<cv::Vec3b>(v, u);
        if (c[0] > 200 && c[1] > 150 && c[1] < 250 && c[2] < 60) return true;
      }
    return false;
  };
  const Polygon& outer = regions.outer;
  int drawn = 0;
  for (std::size_t i = 0; i < outer.size(); ++i) drawn += near_outline(0.5 * (outer[i] + outer[(i + 1) % outer.size()]));
  EXPECT_GE(drawn, static_cast<int>(outer.size()) * 9 / 10);
}

TEST(ArScene, LevelOfErrorShowsItsLevelsSubgraphVideoFillsTheBackgroundLabelsAreDrawn) {
  ar::ArScene scene = box_scene();
  OffscreenView view(scene);
  ASSERT_TRUE(view.usable()) << view.error();
  const Camera& camera = scene.camera();
  scene.set_video(cv::Mat(48, 64, CV_8UC3, cv::Scalar(255, 0, 0)));  // BGR: blue
  int red = 0, green = 0;
  for (int level : {0, 1, 5}) {
    ArFrame frame;
    frame.objects.push_back(frame_of(camera, box_pose(), box_pose(), box_covariance(), level));
    frame.objects[0].label.box = {Vec2(10, 10), Vec2(150, 40)};
    const std::string text[] = {"DRAWER 7"};
    scene.update(frame, text);
    const cv::Mat image = view.render();
    red = green = 0;
    int white_in_label = 0;
    for (int v = 0; v < image.rows; ++v)
      for (int u = 0; u < image.cols; ++u) {
        const cv::Vec3b p = image.at<cv::Vec3b>(v, u);
        red += is_red(p), green += is_green(p);
        if (u >= 10 && u < 150 && v >= 10 && v < 40) white_in_label += p[0] > 200 && p[1] > 200 && p[2] > 200;
      }
    if (level == 0) {
      EXPECT_GT(red, 1000);
      EXPECT_EQ(green, 0);
    } else {  // level 1, and level 5 beyond the last child: the last child
      EXPECT_EQ(red, 0) << "level " << level;
      EXPECT_GT(green, 1000) << "level " << level;
    }
    EXPECT_GT(white_in_label, 30) << "the label's text";
    const cv::Vec3b corner = image.at<cv::Vec3b>(image.rows - 3, image.cols - 3);
    EXPECT_TRUE(corner[2] > 200 && corner[0] < 60 && corner[1] < 60) << "the video behind: " << corner;
  }
}
