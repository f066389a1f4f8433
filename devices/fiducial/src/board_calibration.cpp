#include "board_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <Eigen/Cholesky>
#include <fmt/format.h>
#include <opencv2/core/optim.hpp>

namespace covtrack::fiducial {
namespace {

using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat8 = Eigen::Matrix<double, 8, 8>;
using Mat84 = Eigen::Matrix<double, 8, 4>;

// A gross error: a wrong quad or a tag off its place by a millimetre scores in the
// thousands, while chi-square(8) passes 45 once in a million. Not its 99.9% quantile (26):
// a board's real residuals have a heavier tail than a Gaussian's (code-dependent edge
// errors), and trimming it there left out 3% of a rendered board's residuals and fitted
// the independent factor 7% low (0.75 instead of 0.80), over-confident on held-out tags.
constexpr double kGrossResidualNees = 100;
constexpr double kChi2_6_99 = 16.812;
constexpr int kMinResiduals = 30;
// Passes of building the residuals under the last fit (fit_board_calibration): the
// tests' fits settle in 3 to 5 (each overshoot about a quarter of the one before); a pass
// has settled when it moves every value by less than this many of its standard errors.
constexpr int kMaxPasses = 10;
constexpr double kSettledInSe = 0.1;

// One tag view as the fit sees it (see board_calibration.hpp).
struct Residual {
  Vec8 r;                 // corners (no scale-bias correction) - where the other tags put them
  Vec8 bias_direction;    // M 1: the corners' motion when all four edges move out by 1 px
  // The shapes of the edge, scale and turn terms: M M^T, (M 1)(M 1)^T, N N^T.
  Mat8 edge_shape, scale_shape, tilt_shape;
  Vec8 independent_var;   // the starting model's, per coordinate: floor and pixel axes
  Mat8 line_cov;          //   its edge-line fits' (image noise, per-sample floor)
  Vec8 shift_var;         //   and what its white-cell shift correction misses
  double scale_sd = 0, edge_sd = 0, tilt_sd = 0;  // the starting model's, at this blur
  double polarity_blur = 0;
  Mat8 prediction = Mat8::Zero();  // J P J^T of the other tags' placement
  double blur_px = 0;
};

// b, then log factors kI, kS, kE. The turn and white-cell-shift terms stay at the starting
// model's: a board's tags hardly tell them apart from independent noise. With the turn's
// factor free, the curvature was singular on synthetic boards, and on rendered boards the
// fit moved variance from the independent term (0.80 -> 0.52) to the turn (2.9), which
// sets a pose's depth less: held-out single tags' NEES rose from 5.4-6.0 to 8.4-9.8.
constexpr int kParams = 4;
using Params = std::array<double, kParams>;

Vec8 mean_of(const Residual& v, double b) { return v.bias_direction * (v.polarity_blur * b); }

Mat8 covariance_of(const Residual& v, const Params& p) {
  const double kI = std::exp(p[1]), kS = std::exp(p[2]), kE = std::exp(p[3]);
  const double e2 = std::pow(kE * v.edge_sd, 2), s2 = std::pow(kS * v.scale_sd, 2), t2 = std::pow(v.tilt_sd, 2);
  Mat8 S = e2 * v.edge_shape + s2 * v.scale_shape + t2 * v.tilt_shape + v.prediction;
  S += kI * kI * v.line_cov;
  S.diagonal() += kI * kI * v.independent_var + v.shift_var;
  return S;
}

// Mahalanobis^2 of one residual; log|S| into `log_det` if asked.
double residual_nees(const Residual& v, const Params& p, double* log_det = nullptr) {
  const Eigen::LDLT<Mat8> ldlt(covariance_of(v, p));
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return std::numeric_limits<double>::infinity();
  if (log_det) *log_det = ldlt.vectorD().array().log().sum();
  const Vec8 d = v.r - mean_of(v, p[0]);
  return d.dot(ldlt.solve(d));
}

// The negative log-likelihood (without constants) of the residuals, for OpenCV's simplex.
class NegativeLogLikelihood : public cv::MinProblemSolver::Function {
 public:
  explicit NegativeLogLikelihood(const std::vector<Residual>& residuals) : residuals_(residuals) {}
  int getDims() const override { return kParams; }
  double calc(const double* x) const override {
    for (int i = 1; i < kParams; ++i)
      if (!(std::abs(x[i]) < 6)) return 1e300;  // factors within e^+-6: beyond is no camera
    Params p;
    std::copy(x, x + kParams, p.begin());
    double sum = 0;
    for (const Residual& v : residuals_) {
      double log_det = 0;
      const double m = residual_nees(v, p, &log_det);
      if (!std::isfinite(m)) return 1e300;
      sum += m + log_det;
    }
    return sum;
  }

 private:
  const std::vector<Residual>& residuals_;
};

Params maximise_likelihood(const std::vector<Residual>& residuals, const Params& start) {
  auto solver = cv::DownhillSolver::create();
  solver->setFunction(cv::makePtr<NegativeLogLikelihood>(residuals));
  const cv::Mat step = (cv::Mat_<double>(1, kParams) << 0.1, 0.3, 0.3, 0.3);
  solver->setInitStep(step);
  // Stop when the simplex's log-likelihoods differ by under 1e-3: far below what the data
  // can tell apart (a change of 0.5 is one standard error of one parameter).
  solver->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER + cv::TermCriteria::EPS, 4000, 1e-3));
  cv::Mat x(1, kParams, CV_64F);
  std::copy(start.begin(), start.end(), x.ptr<double>());
  // The simplex can stall on a ridge; restarting it from where it stopped is the usual cure.
  for (int restart = 0; restart < 3; ++restart) solver->minimize(x);
  Params p;
  std::copy(x.ptr<double>(), x.ptr<double>() + kParams, p.begin());
  return p;
}

// Standard errors of the parameters at the optimum `p`: the inverse of the curvature of
// the negative log-likelihood (-2 log L here, hence the factor 2), by central differences.
Params standard_errors(const std::vector<Residual>& residuals, const Params& p) {
  const NegativeLogLikelihood nll(residuals);
  const Params h{0.005, 0.02, 0.02, 0.02};
  const auto at = [&](int i, double di, int j, double dj) {
    Params x = p;
    x[static_cast<std::size_t>(i)] += di, x[static_cast<std::size_t>(j)] += dj;
    return nll.calc(x.data());
  };
  // Symmetric: each pair once (the fit asks for these every pass).
  Eigen::Matrix<double, kParams, kParams> H;
  for (int i = 0; i < kParams; ++i)
    for (int j = i; j < kParams; ++j) {
      const double hi = h[static_cast<std::size_t>(i)], hj = h[static_cast<std::size_t>(j)];
      H(i, j) = H(j, i) = (at(i, hi, j, hj) - at(i, hi, j, -hj) - at(i, -hi, j, hj) + at(i, -hi, j, -hj)) / (4 * hi * hj);
    }
  const Eigen::Matrix<double, kParams, kParams> C = 2 * H.inverse();
  Params se;
  for (int i = 0; i < kParams; ++i) se[static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, C(i, i)));
  return se;
}

CornerNoiseModel without_scale_bias(CornerNoiseModel m) {
  m.scale_bias_per_blur = 0;
  return m;
}

const BundleTag* board_tag(const TagBundle& board, int id) {
  for (const BundleTag& t : board.tags)
    if (t.id == id) return &t;
  return nullptr;
}

// The board's tags in one frame posed under `model` (those the pose refuses are left out).
// Each tag's apparent-scale error is taken as its own, not the frame's (TagPose): the
// residual model above has no term for the correlation between a tag and the tags that
// place it, so they place it as if there were none. A board's pose takes its depth from
// where its tags sit, hardly from their sizes, so a tag's scale error shows in its
// residual either way, and the fitted scale factor is the per-tag spread the driver needs.
std::vector<BundleObservation> pose_tags(const Camera& camera, const TagBundle& board, const BoardFrame& frame,
                                         const CornerNoiseModel& model, double ambiguity_chi2) {
  std::vector<BundleObservation> out;
  for (const BoardDetection& d : frame) {
    const BundleTag* tag = board_tag(board, d.detection.id);
    if (!tag) continue;
    auto pose = estimate_tag_pose(camera, d.detection.corners_px, tag->size_m, model.noise(d.inputs), ambiguity_chi2);
    if (pose) out.push_back({*tag, *pose});
  }
  return with_own_scales(std::move(out));
}

// Every tag view of `frames` with two or more other board tags, predicted from them.
std::vector<Residual> residuals_of(const Camera& camera, const TagBundle& board,
                                   const std::vector<BoardFrame>& frames, const CornerNoiseModel& model,
                                   double ambiguity_chi2, int& frames_used) {
  std::vector<Residual> out;
  const CornerNoiseModel unbiased = without_scale_bias(model);
  frames_used = 0;
  for (const BoardFrame& frame : frames) {
    const auto posed = pose_tags(camera, board, frame, model, ambiguity_chi2);
    if (posed.size() < 3) continue;
    // The whole board first (a tag that disagrees with the rest is left out of it): a frame
    // whose board pose is ambiguous places no tag reliably. Each tag is then placed by the
    // others from there; one that disagrees (a wrong quad, a tag off its place) shows as
    // an outlier in corner space and is left out of the fit.
    const auto whole = estimate_bundle_pose(camera, posed, ambiguity_chi2);
    if (!whole || whole->ambiguous) continue;
    ++frames_used;
    for (std::size_t i = 0; i < posed.size(); ++i) {
      std::vector<BundleObservation> others = posed;
      others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
      const auto placed = refine_bundle_pose(camera, others, whole->T_camera_bundle);
      if (!placed) continue;
      const BundleObservation& me = posed[i];
      const auto det = std::find_if(frame.begin(), frame.end(),
                                    [&](const BoardDetection& d) { return d.detection.id == me.tag.id; });
      const CornerNoise noise = unbiased.noise(det->inputs);
      const auto unbiased_pose =
          estimate_tag_pose(camera, det->detection.corners_px, me.tag.size_m, noise, ambiguity_chi2);
      if (!unbiased_pose) continue;
      Residual v;
      const auto X = tag_corner_points(me.tag.size_m);
      Eigen::Matrix<double, 8, 6> J;
      for (int k = 0; k < 4; ++k) {
        const Vec3 X_board = me.tag.T_bundle_tag * X[k];
        const cv::Point2d p = pinhole_pixel(camera, placed->T_camera_bundle * X_board);
        v.r(2 * k) = unbiased_pose->corners_px[k].x - p.x;
        v.r(2 * k + 1) = unbiased_pose->corners_px[k].y - p.y;
        J.block<2, 6>(2 * k, 0) = point_jacobian(camera, placed->T_camera_bundle, X_board);
        v.independent_var(2 * k) = v.independent_var(2 * k + 1) = noise.sigma_px * noise.sigma_px;
        v.shift_var(2 * k) = v.shift_var(2 * k + 1) = noise.extra_px[k] * noise.extra_px[k];
      }
      const Mat8 modes = edge_line_modes(unbiased_pose->corners_px);
      const Mat84 out_modes = modes.leftCols<4>(), turn_modes = modes.rightCols<4>();
      v.bias_direction = out_modes * Eigen::Vector4d::Ones();
      v.edge_shape = out_modes * out_modes.transpose();
      v.scale_shape = v.bias_direction * v.bias_direction.transpose();
      v.tilt_shape = turn_modes * turn_modes.transpose();
      v.line_cov = std::pow(noise.line_sigma_px, 2) * (v.edge_shape / 4 + 3 * v.tilt_shape / 4);
      v.scale_sd = model.scale_sigma(det->inputs), v.edge_sd = model.edge_sigma(det->inputs);
      v.tilt_sd = model.tilt_sigma(det->inputs);
      v.polarity_blur = det->inputs.polarity * det->inputs.blur_px;
      v.blur_px = det->inputs.blur_px;
      v.prediction = J * placed->covariance * J.transpose();
      if (v.r.allFinite() && v.prediction.allFinite()) out.push_back(v);
    }
  }
  return out;
}

// `start` with this camera's values: each term's coefficients scaled by its factor.
CornerNoiseModel with_factors(CornerNoiseModel m, const Params& p) {
  const double kI = std::exp(p[1]), kS = std::exp(p[2]), kE = std::exp(p[3]);
  m.scale_bias_per_blur = p[0];
  m.gain_px *= kI, m.floor_px *= kI, m.sample_floor_px *= kI, m.aligned_px *= kI;
  m.scale_sigma_px *= kS, m.scale_per_blur *= kS;
  m.edge_sigma_px *= kE, m.edge_per_blur *= kE;
  return m;
}

}  // namespace

BoardFrame find_board(const cv::Mat& gray, TagDetector& detector, const TagBundle& board) {
  const std::vector<Detection> detections = detector.detect(gray);
  std::map<int, int> copies;
  for (const Detection& d : detections) ++copies[d.id];
  const double noise = estimate_image_noise(gray);
  BoardFrame frame;
  for (const Detection& d : detections)
    if (board_tag(board, d.id) && copies[d.id] == 1)
      frame.push_back({d, measure_corner_inputs(gray, d, detector.family(), noise)});
  return frame;
}

BoardConsistency board_consistency(const Camera& camera, const TagBundle& board,
                                   const std::vector<BoardFrame>& frames, const CornerNoiseModel& model,
                                   double ambiguity_chi2) {
  BoardConsistency c;
  std::vector<double> chi2;
  for (const BoardFrame& frame : frames) {
    const auto posed = pose_tags(camera, board, frame, model, ambiguity_chi2);
    if (posed.size() < 2) continue;
    // No limit: every tag is judged against all the others, none left out.
    const auto bundle = estimate_bundle_pose(camera, posed, ambiguity_chi2, std::numeric_limits<double>::infinity());
    if (!bundle) continue;
    for (const TagAgreement& a : bundle->agreement)
      if (std::isfinite(a.chi2)) chi2.push_back(a.chi2);
  }
  if (chi2.empty()) return c;
  c.tags = static_cast<int>(chi2.size());
  double sum = 0;
  int above = 0;
  for (double x : chi2) sum += x, above += x > kChi2_6_99;
  c.mean_chi2 = sum / c.tags, c.above_99 = static_cast<double>(above) / c.tags;
  std::nth_element(chi2.begin(), chi2.begin() + c.tags / 2, chi2.end());
  c.median_chi2 = chi2[static_cast<std::size_t>(c.tags / 2)];
  return c;
}

Result<BoardFit> fit_board_calibration(const Camera& camera, const TagBundle& board,
                                       const std::vector<BoardFrame>& frames, const CornerNoiseModel& start,
                                       double ambiguity_chi2) {
  BoardFit fit;
  Params p{start.scale_bias_per_blur, 0, 0, 0};
  std::vector<Residual> used;
  // The residuals are built under a model: it corrects the scale bias before the tags
  // place each other, and it sets the covariance of that placement (Residual::prediction),
  // which the likelihood takes as known. Fitted under a model whose edge factor is too
  // small, the placement's error is underrated and the fit puts it into the tag's own
  // terms; under one too large, the reverse: the fit over- and undershoots in turn (edge
  // factor 2.00 drawn: 2.16 under the starting model, 1.84 under that). So the residuals are
  // rebuilt under each fit until a pass moves no value by a tenth of its standard error
  // (the model the residuals are built under is then the one they fit).
  for (int pass = 1;; ++pass) {
    const CornerNoiseModel model = with_factors(start, p);
    std::vector<Residual> all = residuals_of(camera, board, frames, model, ambiguity_chi2, fit.frames_used);
    if (static_cast<int>(all.size()) < kMinResiduals)
      return fail(fmt::format("only {} tag views could be predicted from the board's other tags in {} frames "
                              "(at least {} needed): each frame needs three of the board's tags or more",
                              all.size(), frames.size(), kMinResiduals));
    // The residuals were built under `model`: its factors are 1 there, its bias the same.
    Params q{p[0], 0, 0, 0};
    q = maximise_likelihood(all, q);
    used.clear();
    for (const Residual& v : all)
      if (residual_nees(v, q) < kGrossResidualNees) used.push_back(v);
    fit.left_out = static_cast<int>(all.size() - used.size());
    if (static_cast<int>(used.size()) < kMinResiduals) return fail("too many tag views disagree with their board");
    q = maximise_likelihood(used, q);
    const Params se = standard_errors(used, q);
    fit.settled = std::abs(q[0] - p[0]) < kSettledInSe * se[0];
    // Compose with the model the residuals were built under.
    p[0] = q[0];
    for (std::size_t i = 1; i < kParams; ++i) {
      p[i] += q[i];
      fit.settled = fit.settled && std::abs(q[i]) < kSettledInSe * se[i];
    }
    double nees = 0;
    for (const Residual& v : used) nees += residual_nees(v, q);
    fit.mean_residual_nees = nees / static_cast<double>(used.size());
    fit.scale_bias_se = se[0];
    // A log factor's standard error is its factor's relative one.
    fit.independent_se = std::exp(p[1]) * se[1], fit.scale_se = std::exp(p[2]) * se[2];
    fit.edge_se = std::exp(p[3]) * se[3];
    fit.passes = pass;
    if (fit.settled || pass == kMaxPasses) break;
  }
  fit.model = with_factors(start, p);
  fit.scale_bias_per_blur = p[0];
  fit.independent_factor = std::exp(p[1]), fit.scale_factor = std::exp(p[2]);
  fit.edge_factor = std::exp(p[3]);
  fit.residuals = static_cast<int>(used.size());
  std::vector<double> blur;
  for (const Residual& v : used) blur.push_back(v.blur_px);
  std::nth_element(blur.begin(), blur.begin() + static_cast<std::ptrdiff_t>(blur.size() / 2), blur.end());
  fit.median_blur_px = blur[blur.size() / 2];
  fit.before = board_consistency(camera, board, frames, start, ambiguity_chi2);
  fit.after = board_consistency(camera, board, frames, fit.model, ambiguity_chi2);
  return fit;
}

}  // namespace covtrack::fiducial
