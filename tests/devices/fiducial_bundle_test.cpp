// Tag bundles: one pose for a rigid set of tags from all their corners.
//  - The maths alone: corners drawn from exactly the covariance the model states give a
//    bundle NEES of chi-square(6), and tags that agree at the limit's rate.
//  - On renders from the held-out side of the corner model's calibration (the random-point
//    rasteriser, an 800x600 camera, the validation families), with tags smaller than the
//    calibration's and shapes it never saw (a flat board of six tags of two sizes, a tent
//    of four tags on two panels at +-30 degrees): the bundle's NEES against its true pose,
//    its precision against its best single tag and against a fit that takes each tag's
//    apparent-scale error as its own, and how rarely consistent bundles are called
//    DEGRADED. Each frame is one random camera of the calibration's population, so frames
//    are independent draws of the systematic corner errors.
//  - The same renders' corner errors split by the corner model's terms (apparent scale,
//    each edge's placement, each edge's turn) against the model's variance of each, and
//    the apparent scale's correlation between the tags of one frame.
//  - A board whose tag sits 2 cm from where its config says: DEGRADED, the tag named and
//    left out, the truth inside the 99% region.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>

#include <Eigen/Eigenvalues>

#include "bundle_pose.hpp"
#include "corner_noise.hpp"
#include "fiducial_scene.hpp"
#include "tag_detector.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;

namespace {

constexpr double kChi2_6_99 = 16.812;

// The detected square of a tag printed `printed_m` wide (for some families the printed tag
// reaches well beyond the square the detector finds: tagCircle49h12's is 5 of 11 cells).
double detected_size(const TagFamily& family, double printed_m) {
  return printed_m * family.cells_across_border() / family.cells_across_total();
}

// Six tags printed 0.065 and 0.055 m wide on a flat board, 0.08 m apart.
std::vector<BundleTag> board(const TagFamily& family) {
  std::vector<BundleTag> tags;
  for (int id = 0; id < 6; ++id) {
    Pose T = Pose::Identity();
    T.translation() = Vec3((id % 3 - 1) * 0.08, (id / 3 - 0.5) * 0.08, 0);
    tags.push_back({id, detected_size(family, id % 2 ? 0.055 : 0.065), T});
  }
  return tags;
}

// A tent: two panels meeting in a ridge along the bundle's y axis, towards the camera,
// each turned 30 degrees away; two tags printed 0.06 m wide per panel.
std::vector<BundleTag> tent(const TagFamily& family) {
  std::vector<BundleTag> tags;
  const double angle = 30 * M_PI / 180, along = 0.05;  // a tag centre's distance from the ridge
  for (int id = 0; id < 4; ++id) {
    const double side = id < 2 ? -1 : 1;
    Pose T = Pose::Identity();
    T.linear() = Eigen::AngleAxisd(-side * angle, Vec3::UnitY()).toRotationMatrix();
    T.translation() = Vec3(side * along * std::cos(angle), (id % 2 - 0.5) * 0.075, along * std::sin(angle));
    tags.push_back({id, detected_size(family, 0.06), T});
  }
  return tags;
}

// A bundle 0.4-0.65 m ahead, turned by up to 30 degrees either way and rolled freely.
Pose random_bundle_pose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  return test::tag_pose(0.525 + 0.125 * u(rng), 30 * u(rng), 20 * u(rng), 180 * u(rng), 0.04 * u(rng),
                        0.03 * u(rng));
}

double nees(const Pose& truth, const Pose& estimate, const Mat6& covariance) {
  const Vec6 e = boxminus(truth, estimate);
  return e.dot(covariance.ldlt().solve(e));
}

// The NEES split along the covariance's principal directions, tightest first: each entry
// is 1 on average when the covariance is right in that direction.
Vec6 nees_by_direction(const Pose& truth, const Pose& estimate, const Mat6& covariance) {
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(covariance);
  const Vec6 z = eig.eigenvectors().transpose() * boxminus(truth, estimate);
  return z.cwiseProduct(z).cwiseQuotient(eig.eigenvalues());
}

struct FrameResult {
  bool tent = false;
  Pose truth;  // T_camera_bundle
  std::optional<BundlePose> bundle;
  std::optional<BundlePose> bundle_own_scales;  // each tag's apparent-scale error taken as its own
  std::optional<Pose> best_tag;  // the most precise single tag's pose, mapped to the bundle
  Mat6 best_tag_covariance = Mat6::Zero();
  std::vector<BundleObservation> seen;  // the bundle's tags as posed on their own
};

// Renders bundles and poses them as the driver does (detection, corner model, tag poses,
// bundle), with the shipped defaults throughout.
class Renderer {
 public:
  static constexpr int kFamilies = 4;

  Renderer() {
    for (const char* family : {"tag25h9", "tagStandard52h13", "tagCircle49h12", "tagCustom48h12"}) {
      DetectorOptions o;
      o.family = family;
      o.decimate = 1;
      auto d = TagDetector::create(o);
      EXPECT_TRUE(d.has_value()) << d.error().message;
      if (d) detectors_.push_back(std::move(*d));
    }
  }

  const Camera& camera() const { return camera_; }
  const TagFamily& family(int f) const { return detectors_[static_cast<std::size_t>(f)]->family(); }

  // Renders `rendered` (the tags where they really are on the bundle) at T_camera_bundle in
  // family `f` and solves the bundle as `configured` says it is.
  FrameResult frame(int f, const std::vector<BundleTag>& configured, const std::vector<BundleTag>& rendered,
                    const Pose& T_camera_bundle, std::mt19937_64& rng) {
    TagDetector& detector = *detectors_[static_cast<std::size_t>(f)];
    std::vector<RenderedTag> scene;
    for (const BundleTag& t : rendered) scene.push_back({t.id, t.size_m, T_camera_bundle * t.T_bundle_tag});
    const ImageFormation formation = test::random_formation(rng, Rasteriser::JitteredPoints);
    const cv::Mat image = form_image(camera_, detector.family(), scene, formation, rng);
    const double noise = estimate_image_noise(image);
    FrameResult out;
    out.truth = T_camera_bundle;
    double best_det = std::numeric_limits<double>::infinity();
    for (const Detection& d : detector.detect(image)) {
      const auto tag =
          std::find_if(configured.begin(), configured.end(), [&](const BundleTag& t) { return t.id == d.id; });
      if (tag == configured.end()) continue;
      const CornerNoise corner_noise = model_.noise(measure_corner_inputs(image, d, detector.family(), noise));
      auto pose = estimate_tag_pose(camera_, d.corners_px, tag->size_m, corner_noise);
      if (!pose) continue;  // a tag cut by the frame's edge is refused
      out.seen.push_back({*tag, *pose});
      // The best single tag: the smallest covariance of the pose it gives the bundle.
      const Mat6 A = se3_adjoint(tag->T_bundle_tag);
      const Mat6 C = A * pose->covariance * A.transpose();
      if (C.determinant() < best_det) {
        best_det = C.determinant();
        out.best_tag = pose->best.T_camera_tag * tag->T_bundle_tag.inverse();
        out.best_tag_covariance = C;
      }
    }
    if (!out.seen.empty()) {
      auto b = estimate_bundle_pose(camera_, out.seen);  // the driver's default limits
      EXPECT_TRUE(b.has_value()) << b.error().message;
      if (b) out.bundle = *b;
      if (auto own = estimate_bundle_pose(camera_, with_own_scales(out.seen))) out.bundle_own_scales = *own;
    }
    return out;
  }

 private:
  Camera camera_ = test::camera(800, 600, 58);
  CornerNoiseModel model_;
  std::vector<std::unique_ptr<TagDetector>> detectors_;
};

// The consistent bundles, rendered once for the tests that judge them: boards and tents in
// turn, each in every family.
const std::vector<FrameResult>& consistent_frames() {
  static const std::vector<FrameResult> frames = [] {
    Renderer renderer;
    std::mt19937_64 rng(57);
    std::vector<FrameResult> out;
    for (int i = 0; i < 120; ++i) {
      const bool is_tent = i % 2;
      const int f = (i / 2) % Renderer::kFamilies;
      const auto layout = is_tent ? tent(renderer.family(f)) : board(renderer.family(f));
      out.push_back(renderer.frame(f, layout, layout, random_bundle_pose(rng), rng));
      out.back().tent = is_tent;
    }
    return out;
  }();
  return frames;
}

// The 99% bounds of the mean of n independent chi-square(6) draws.
std::pair<double, double> mean_bounds(int n) {
  const double half_width = 2.576 * std::sqrt(12.0 / n);
  return {6 - half_width, 6 + half_width};
}

// Two estimates of the same poses: their RMS position and rotation errors side by side.
struct ErrorPair {
  double position_sq[2] = {0, 0}, rotation_sq[2] = {0, 0};
  int n = 0;
  void add(const Vec6& first, const Vec6& second) {
    position_sq[0] += first.head<3>().squaredNorm(), position_sq[1] += second.head<3>().squaredNorm();
    rotation_sq[0] += first.tail<3>().squaredNorm(), rotation_sq[1] += second.tail<3>().squaredNorm();
    ++n;
  }
  double mm(int i) const { return std::sqrt(position_sq[i] / n) * 1e3; }
  double deg(int i) const { return std::sqrt(rotation_sq[i] / n) * 180 / M_PI; }
  double position_ratio() const { return std::sqrt(position_sq[0] / position_sq[1]); }
  double rotation_ratio() const { return std::sqrt(rotation_sq[0] / rotation_sq[1]); }
};

}  // namespace

// Catches a wrong Jacobian, a wrong adjoint, or a joint covariance unlike the one the
// corners are drawn from (each tag's own errors per tag, the apparent scale once per frame;
// drawn once per tag, they read 9.2). A fit that drops the shared scale still passes (6.04):
// SharingTheFramesApparentScaleMakesItMorePrecise catches that. Also catches an agreement
// test whose covariance is off (the others' covariance taken 0.7x reads 6.44).
TEST(FiducialBundle, CovarianceIsExactForCornersDrawnFromTheModel) {
  constexpr double kChi2_6_999 = 22.458;
  const Camera cam = test::camera(800, 600, 58);
  auto family = TagFamily::open("tag36h11");
  ASSERT_TRUE(family.has_value());
  CornerNoise noise;  // systematic terms as large as the defaults give a blurred tag
  noise.sigma_px = 0.08, noise.scale_sigma_px = 0.1, noise.edge_sigma_px = 0.04, noise.tilt_sigma_px = 0.03;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss;
  double sum = 0, agreement_sum = 0;
  int n = 0, disagree = 0, tags = 0, agreements = 0;
  for (int draw = 0; draw < 1000; ++draw) {
    const auto layout = draw % 2 ? tent(**family) : board(**family);
    const Pose T_camera_bundle = random_bundle_pose(rng);
    std::vector<BundleObservation> seen;
    const double frame_scale = gauss(rng);  // the apparent-scale error every tag of the frame shares
    for (const BundleTag& t : layout) {
      const auto X = tag_corner_points(t.size_m);
      std::array<cv::Point2d, 4> corners;
      for (int k = 0; k < 4; ++k) corners[k] = pinhole_pixel(cam, T_camera_bundle * t.T_bundle_tag * X[k]);
      const Eigen::Matrix<double, 8, 1> s = apparent_scale_mode(corners, noise);
      const Eigen::Matrix<double, 8, 8> L = (corner_covariance(corners, noise) - s * s.transpose()).llt().matrixL();
      Eigen::Matrix<double, 8, 1> z;
      for (int i = 0; i < 8; ++i) z(i) = gauss(rng);
      const Eigen::Matrix<double, 8, 1> e = L * z + s * frame_scale;
      for (int k = 0; k < 4; ++k) corners[k] += cv::Point2d(e(2 * k), e(2 * k + 1));
      auto pose = estimate_tag_pose(cam, corners, t.size_m, noise);
      if (pose) seen.push_back({t, *pose});  // else too near the frame's edge
    }
    if (seen.size() < 2) continue;
    auto b = estimate_bundle_pose(cam, seen, 40, kChi2_6_999);
    ASSERT_TRUE(b.has_value()) << b.error().message;
    sum += nees(T_camera_bundle, b->T_camera_bundle, b->covariance), ++n;
    disagree += b->disagree, tags += static_cast<int>(seen.size());
    for (const TagAgreement& a : b->agreement) agreement_sum += a.chi2, ++agreements;
  }
  const auto [lo, hi] = mean_bounds(n);
  std::printf("corners drawn from the model: bundle NEES %.3f over %d draws (99%% bounds [%.3f, %.3f]); %d of %d "
              "tags disagree at chi-square(6)'s 99.9%% quantile\n",
              sum / n, n, lo, hi, disagree, tags);
  EXPECT_GE(n, 950);
  EXPECT_GT(sum / n, lo);
  EXPECT_LT(sum / n, hi);
  EXPECT_LE(disagree, 3 * tags / 1000 + 3) << "about 1 in 1000 tags should disagree";
  // Each tag against the others: chi-square(6) when the test's covariance is the
  // difference's. A frame's tags share the scale error and the others' poses, so their
  // values are not independent: bounds for the number of frames, not of tags.
  const auto [agreement_lo, agreement_hi] = mean_bounds(n);
  std::printf("tag against the others: mean chi2 %.3f over %d tags (bounds [%.3f, %.3f])\n",
              agreement_sum / agreements, agreements, agreement_lo, agreement_hi);
  EXPECT_GT(agreement_sum / agreements, agreement_lo);
  EXPECT_LT(agreement_sum / agreements, agreement_hi);
}

TEST(FiducialBundle, NeesOfTheBundlePoseOnHeldOutRenders) {
  const auto& frames = consistent_frames();
  double sum[2] = {0, 0};
  Vec6 by_direction[2] = {Vec6::Zero(), Vec6::Zero()};
  int n[2] = {0, 0}, degraded = 0, outside = 0, tags = 0;
  for (const FrameResult& f : frames) {
    if (!f.bundle || f.bundle->ids.size() + f.bundle->left_out.size() < 2) continue;
    const double v = nees(f.truth, f.bundle->T_camera_bundle, f.bundle->covariance);
    by_direction[f.tent] += nees_by_direction(f.truth, f.bundle->T_camera_bundle, f.bundle->covariance);
    sum[f.tent] += v, ++n[f.tent], outside += v > kChi2_6_99;
    tags += static_cast<int>(f.seen.size());
    degraded += f.bundle->degraded();
    if (f.bundle->degraded()) std::printf("DEGRADED (%s): %s\n", f.tent ? "tent" : "board", f.bundle->why_degraded.c_str());
  }
  const int all = n[0] + n[1];
  const auto [lo, hi] = mean_bounds(all);
  const auto [tent_lo, tent_hi] = mean_bounds(n[1]);
  const auto [board_lo, board_hi] = mean_bounds(n[0]);
  std::printf("bundle NEES: all %.2f over %d frames ([%.2f, %.2f]), %.1f tags each; boards %.2f over %d "
              "([%.2f, %.2f]); tents %.2f over %d ([%.2f, %.2f]); truth outside the 99%% region %d; DEGRADED %d\n",
              (sum[0] + sum[1]) / all, all, lo, hi, double(tags) / all, sum[0] / n[0], n[0], board_lo, board_hi,
              sum[1] / n[1], n[1], tent_lo, tent_hi, outside, degraded);
  for (int tent = 0; tent < 2; ++tent) {
    const Vec6 d = by_direction[tent] / n[tent];
    std::printf("%s NEES along the covariance's principal directions, tightest first (1 each when right): %.2f %.2f "
                "%.2f %.2f %.2f %.2f\n",
                tent ? "tents" : "boards", d(0), d(1), d(2), d(3), d(4), d(5));
  }
  EXPECT_GE(all, static_cast<int>(frames.size()) * 9 / 10) << "too few bundles posed";
  // Never over-confident: every mean below chi-square(6)'s upper 99% bound.
  EXPECT_LT((sum[0] + sum[1]) / all, hi);
  EXPECT_LT(sum[0] / n[0], board_hi);
  EXPECT_LT(sum[1] / n[1], tent_hi);
  // Tents (a non-planar object) and flat boards within both bounds. (Boards were 1.6-2.2x
  // under-confident until the image noise was measured through JPEG and the model put the
  // line fit's variance where a line fit puts it, and 1.26x (4.78) until the calibration's
  // renders formed a distorted camera's image as a lens does and an edge's own spreads fell
  // with its length: devices/fiducial/README.md.)
  EXPECT_GT(sum[1] / n[1], tent_lo);
  EXPECT_GT(sum[0] / n[0], board_lo) << "flat boards under-confident";
  // Consistent tags are rarely called inconsistent at the default limit.
  EXPECT_LE(degraded * 100, all * 5) << "consistent bundles DEGRADED";
}

TEST(FiducialBundle, IsMorePreciseThanItsBestSingleTag) {
  ErrorPair e;
  double sigma_ratio = 0;
  for (const FrameResult& f : consistent_frames()) {
    if (!f.bundle || f.bundle->ids.size() < 2) continue;
    e.add(boxminus(f.truth, f.bundle->T_camera_bundle), boxminus(f.truth, *f.best_tag));
    sigma_ratio += std::sqrt(f.bundle->covariance.topLeftCorner<3, 3>().trace() /
                             f.best_tag_covariance.topLeftCorner<3, 3>().trace());
  }
  ASSERT_GT(e.n, 0);
  std::printf("RMS error at the bundle's origin, bundle / best single tag: position %.2f / %.2f mm (%.2f), "
              "rotation %.3f / %.3f deg (%.2f); reported position sigma %.2f of the tag's (mean over %d frames)\n",
              e.mm(0), e.mm(1), e.position_ratio(), e.deg(0), e.deg(1), e.rotation_ratio(), sigma_ratio / e.n, e.n);
  EXPECT_LT(e.position_ratio(), 0.5);
  EXPECT_LT(e.rotation_ratio(), 0.5);
  EXPECT_LT(sigma_ratio / e.n, 0.5);
}

// The tags of one frame share their apparent-scale error (ResidualsByTermOnHeldOutRenders
// measures it): fitted as the frame's, the bundle is more precise than fitted as if each
// tag's were its own, and as honest.
TEST(FiducialBundle, SharingTheFramesApparentScaleMakesItMorePrecise) {
  ErrorPair e;
  double nees_shared = 0, nees_own = 0;
  for (const FrameResult& f : consistent_frames()) {
    if (!f.bundle || !f.bundle_own_scales || f.bundle->ids.size() < 2) continue;
    e.add(boxminus(f.truth, f.bundle->T_camera_bundle), boxminus(f.truth, f.bundle_own_scales->T_camera_bundle));
    nees_shared += nees(f.truth, f.bundle->T_camera_bundle, f.bundle->covariance);
    nees_own += nees(f.truth, f.bundle_own_scales->T_camera_bundle, f.bundle_own_scales->covariance);
  }
  ASSERT_GT(e.n, 100);
  std::printf("RMS error at the bundle's origin, the frame's scale shared / each tag's own: position %.3f / %.3f mm "
              "(%.2f), rotation %.4f / %.4f deg (%.2f); NEES %.2f / %.2f over %d frames\n",
              e.mm(0), e.mm(1), e.position_ratio(), e.deg(0), e.deg(1), e.rotation_ratio(), nees_shared / e.n,
              nees_own / e.n, e.n);
  EXPECT_LT(e.position_ratio(), 0.85);
  EXPECT_LT(e.rotation_ratio(), 0.9);
}

TEST(FiducialBundle, ATagMovedOnTheBoardIsFoundLeftOutAndCovered) {
  constexpr int kMoved = 4, kFrames = 32;
  Renderer renderer;
  std::mt19937_64 rng(61);
  int n = 0, degraded = 0, named = 0, inside = 0, inside_plain = 0;
  for (int i = 0; i < kFrames; ++i) {
    const int f = i % Renderer::kFamilies;
    const auto configured = board(renderer.family(f));
    auto rendered = configured;
    rendered[kMoved].T_bundle_tag.translation() += Vec3(0, 0.02, 0);  // 2 cm along the board, outward
    const FrameResult r = renderer.frame(f, configured, rendered, random_bundle_pose(rng), rng);
    if (!r.bundle || r.seen.size() < 3) continue;
    ++n;
    degraded += r.bundle->disagree;
    named += r.bundle->left_out == std::vector<int>{kMoved} &&
             r.bundle->why_degraded.find("tag 4 is") != std::string::npos;
    inside += nees(r.truth, r.bundle->T_camera_bundle, r.bundle->covariance) <= kChi2_6_99;
    // All tags fitted together, with no limit: the moved tag pulls the pose off.
    const auto plain = estimate_bundle_pose(renderer.camera(), r.seen, 40, std::numeric_limits<double>::infinity());
    ASSERT_TRUE(plain.has_value());
    inside_plain += nees(r.truth, plain->T_camera_bundle, plain->covariance) <= kChi2_6_99;
    if (i < 2) std::printf("frame %d: %s\n", i, r.bundle->why_degraded.c_str());
  }
  std::printf("tag %d moved 2 cm: %d frames, DEGRADED %d, tag %d alone left out and named %d, truth inside the 99%% "
              "region %d (all tags fitted together: %d)\n",
              kMoved, n, degraded, kMoved, named, inside, inside_plain);
  EXPECT_GE(n, kFrames * 9 / 10);
  EXPECT_EQ(degraded, n);
  EXPECT_GE(named, n * 9 / 10);
  EXPECT_GE(inside, n * 95 / 100);
  EXPECT_LT(inside_plain, n / 2) << "the moved tag must matter, or this test shows nothing";
}

// The corner residuals of the bundles' tags against their true corners, split by the
// model's terms: each tag's 8 corner errors are exactly 4 edge offsets and 4 edge turns
// (edge_line_modes is invertible); the offsets split into their mean (the tag's apparent
// scale) and the rest (each edge's own placement). Each part's mean square is set against
// the model's variance of that part (devices/fiducial/README.md, "Still weak"), and the
// scale's correlation between tags of one frame is measured.
TEST(FiducialBundle, ResidualsByTermOnHeldOutRenders) {
  const Camera cam = test::camera(800, 600, 58);
  struct Parts {
    double observed[3] = {0, 0, 0}, modelled[3] = {0, 0, 0};  // scale, edge placement, turns
    double scale_products = 0;  // over pairs of tags of one frame
    int tags = 0, pairs = 0;
  } parts[2];
  for (const FrameResult& f : consistent_frames()) {
    if (!f.bundle || f.seen.size() < 2) continue;
    Parts& p = parts[f.tent];
    std::vector<double> scale;
    for (const BundleObservation& o : f.seen) {
      const auto X = tag_corner_points(o.tag.size_m);
      Eigen::Matrix<double, 8, 1> d;
      for (int k = 0; k < 4; ++k) {
        const cv::Point2d t = pinhole_pixel(cam, f.truth * (o.tag.T_bundle_tag * X[k]));
        d(2 * k) = o.pose.corners_px[k].x - t.x, d(2 * k + 1) = o.pose.corners_px[k].y - t.y;
      }
      const Eigen::Matrix<double, 8, 8> to_modes = edge_line_modes(o.pose.corners_px).inverse();
      const Eigen::Matrix<double, 8, 1> q = to_modes * d;
      const Eigen::Matrix<double, 8, 8> C = to_modes * o.pose.corner_covariance * to_modes.transpose();
      const Eigen::Matrix4d rest = Eigen::Matrix4d::Identity() - Eigen::Matrix4d::Constant(0.25);
      const Eigen::Matrix4d offsets = C.topLeftCorner<4, 4>();
      const double s = q.head<4>().mean();
      p.observed[0] += s * s, p.modelled[0] += offsets.sum() / 16;
      p.observed[1] += (rest * q.head<4>()).squaredNorm(), p.modelled[1] += (rest * offsets * rest).trace();
      p.observed[2] += q.tail<4>().squaredNorm(), p.modelled[2] += C.bottomRightCorner<4, 4>().trace();
      scale.push_back(s);
      ++p.tags;
    }
    for (std::size_t i = 0; i < scale.size(); ++i)
      for (std::size_t j = i + 1; j < scale.size(); ++j)
        p.scale_products += scale[i] * scale[j], ++p.pairs;
  }
  for (int tent = 0; tent < 2; ++tent) {
    const Parts& p = parts[tent];
    const double corr = (p.scale_products / p.pairs) / (p.observed[0] / p.tags);
    std::printf("%s tags (%d): observed / modelled mean square: apparent scale %.4f / %.4f px^2 (%.2f), edge placement "
                "%.4f / %.4f (%.2f), edge turns %.4f / %.4f (%.2f); scale correlation between tags of a frame %.2f\n",
                tent ? "tent" : "board", p.tags, p.observed[0] / p.tags, p.modelled[0] / p.tags,
                p.observed[0] / p.modelled[0], p.observed[1] / p.tags, p.modelled[1] / p.tags,
                p.observed[1] / p.modelled[1], p.observed[2] / p.tags, p.modelled[2] / p.tags,
                p.observed[2] / p.modelled[2], corr);
    ASSERT_GT(p.tags, 100);
    // The apparent-scale error is the frame's, not each tag's: the bundle's joint corner
    // covariance shares it between the tags (bundle_pose.hpp).
    EXPECT_GT(corr, 0.8) << (tent ? "tent" : "board");
    // The model's total within 2x of what these renders show: how it splits that total
    // is what the README's figures judge.
    const double observed = p.observed[0] + p.observed[1] + p.observed[2];
    const double modelled = p.modelled[0] + p.modelled[1] + p.modelled[2];
    EXPECT_GT(observed / modelled, 0.5) << (tent ? "tent" : "board");
    EXPECT_LT(observed / modelled, 2.0) << (tent ? "tent" : "board");
  }
}
