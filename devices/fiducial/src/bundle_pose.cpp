#include "bundle_pose.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <fmt/ranges.h>

namespace covtrack::fiducial {
namespace {

using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat8 = Eigen::Matrix<double, 8, 8>;

// One tag's corners as the bundle's fit sees them: where they are on the bundle, where
// they were measured, the whitening W_i of the tag's own errors (W_i^T W_i = B_i^-1,
// B_i = Sigma_i - s_i s_i^T: its corner covariance without the apparent scale s_i, which
// the frame's tags share) and b_i = W_i s_i.
struct TagCorners {
  std::array<Vec3, 4> X_bundle;
  Vec8 measured;
  Mat8 whiten;
  Vec8 whitened_scale;
};

// Tags fitted together. Their joint corner covariance is Sigma = blockdiag(B_i) + s s^T
// (s the s_i stacked: bundle_pose.hpp). With W = blockdiag(W_i) and b = W s,
// Sigma^-1 = W^T (I - b b^T / (1 + b^T b)) W = W^T P^T P W,  P = I - c u u^T,
// u = b / |b|, c = 1 - 1 / sqrt(1 + b^T b): each tag is whitened on its own and the
// stacked result corrected along one direction, so a fit costs about what it would with
// the tags independent.
struct CornerSet {
  std::vector<TagCorners> tags;
  Eigen::VectorXd shared;  // u (zero when no tag has a scale term)
  double shrink = 0;       // c
};

struct Fit {
  Pose T = Pose::Identity();
  Mat6 covariance = Mat6::Zero();
  double cost = std::numeric_limits<double>::infinity();  // sum of squared whitened residuals
};

CornerSet corner_set(std::vector<TagCorners> tags) {
  CornerSet set{std::move(tags), Eigen::VectorXd(), 0};
  set.shared.resize(8 * static_cast<Eigen::Index>(set.tags.size()));
  for (std::size_t i = 0; i < set.tags.size(); ++i)
    set.shared.segment<8>(8 * static_cast<Eigen::Index>(i)) = set.tags[i].whitened_scale;
  const double b2 = set.shared.squaredNorm();
  if (b2 > 0) set.shared /= std::sqrt(b2), set.shrink = 1 - 1 / std::sqrt(1 + b2);
  return set;
}

CornerSet subset(const CornerSet& all, const std::vector<std::size_t>& which) {
  std::vector<TagCorners> tags;
  for (std::size_t i : which) tags.push_back(all.tags[i]);
  return corner_set(std::move(tags));
}

Result<TagCorners> corners_of(const BundleObservation& o) {
  TagCorners t;
  const auto X = tag_corner_points(o.tag.size_m);
  for (int k = 0; k < 4; ++k) {
    t.X_bundle[k] = o.tag.T_bundle_tag * X[k];
    t.measured(2 * k) = o.pose.corners_px[k].x, t.measured(2 * k + 1) = o.pose.corners_px[k].y;
  }
  const Vec8& s = o.pose.apparent_scale_px;
  const Eigen::LLT<Mat8> llt(o.pose.corner_covariance - s * s.transpose());
  if (llt.info() != Eigen::Success)
    return fail(fmt::format("tag {}: corner covariance is not positive definite beyond its apparent-scale part",
                            o.tag.id));
  t.whiten = llt.matrixL().solve(Mat8::Identity());
  t.whitened_scale = t.whiten * s;
  return t;
}

// Every observation's corners, in the order given.
Result<CornerSet> corners_of_all(const std::vector<BundleObservation>& observations) {
  std::vector<TagCorners> tags;
  for (const auto& o : observations) {
    auto t = corners_of(o);
    if (!t) return std::unexpected(t.error());
    tags.push_back(*t);
  }
  return corner_set(std::move(tags));
}

// Whitened residuals of the tags' corners at T; false when a corner is behind the camera.
bool residuals(const Camera& cam, const CornerSet& set, const Pose& T, Eigen::VectorXd& r) {
  r.resize(8 * static_cast<Eigen::Index>(set.tags.size()));
  for (std::size_t i = 0; i < set.tags.size(); ++i) {
    Vec8 d;
    for (int k = 0; k < 4; ++k) {
      const Vec3 p = T * set.tags[i].X_bundle[k];
      if (!(p.z() > 0)) return false;
      const cv::Point2d u = pinhole_pixel(cam, p);
      d(2 * k) = set.tags[i].measured(2 * k) - u.x, d(2 * k + 1) = set.tags[i].measured(2 * k + 1) - u.y;
    }
    r.segment<8>(8 * static_cast<Eigen::Index>(i)) = set.tags[i].whiten * d;
  }
  r -= set.shrink * set.shared.dot(r) * set.shared;
  return true;
}

double cost_at(const Camera& cam, const CornerSet& set, const Pose& T) {
  Eigen::VectorXd r;
  return residuals(cam, set, T, r) ? r.squaredNorm() : std::numeric_limits<double>::infinity();
}

// J^T Sigma^-1 J at T (the information of the BODY perturbation) and J^T Sigma^-1 r.
void normal_equations(const Camera& cam, const CornerSet& set, const Pose& T, Mat6& H, Vec6& g) {
  Eigen::VectorXd r;
  residuals(cam, set, T, r);
  Eigen::Matrix<double, Eigen::Dynamic, 6> Jw(8 * static_cast<Eigen::Index>(set.tags.size()), 6);
  for (std::size_t i = 0; i < set.tags.size(); ++i) {
    Eigen::Matrix<double, 8, 6> J;
    for (int k = 0; k < 4; ++k) J.block<2, 6>(2 * k, 0) = point_jacobian(cam, T, set.tags[i].X_bundle[k]);
    Jw.block<8, 6>(8 * static_cast<Eigen::Index>(i), 0) = set.tags[i].whiten * J;
  }
  Jw -= set.shrink * set.shared * (set.shared.transpose() * Jw);
  H = Jw.transpose() * Jw;
  g = Jw.transpose() * r;
}

// Gauss-Newton from T0, halving a step that does not lower the cost.
Fit gauss_newton(const Camera& cam, const CornerSet& tags, const Pose& T0) {
  Fit f{T0, Mat6::Zero(), cost_at(cam, tags, T0)};
  if (!std::isfinite(f.cost)) return f;
  Mat6 H;
  Vec6 g;
  for (int iteration = 0; iteration < 30; ++iteration) {
    normal_equations(cam, tags, f.T, H, g);
    const Vec6 step = H.ldlt().solve(g);
    // Done when the step would lower the cost (a chi-square) by less than 1e-6.
    if (!step.allFinite() || g.dot(step) < 1e-6) break;
    bool lowered = false;
    for (double scale = 1; scale > 1e-3 && !lowered; scale /= 2) {
      const Pose T = boxplus(f.T, scale * step);
      const double c = cost_at(cam, tags, T);
      if (c < f.cost) f.T = T, f.cost = c, lowered = true;
    }
    if (!lowered) break;
  }
  normal_equations(cam, tags, f.T, H, g);
  f.covariance = H.ldlt().solve(Mat6::Identity());
  f.covariance = (f.covariance + f.covariance.transpose()) / 2;
  return f;
}

// The part of a symmetric matrix with non-negative eigenvalues.
Mat6 positive_part(const Mat6& m) {
  const Eigen::SelfAdjointEigenSolver<Mat6> eig((m + m.transpose()) / 2);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0).asDiagonal() * eig.eigenvectors().transpose();
}

// The bundle is this one tag's pose, mapped: T_camera_tag Exp(xi_tag) T_bundle_tag^-1 =
// T_camera_bundle Exp(Ad(T_bundle_tag) xi_tag).
BundlePose from_one_tag(const BundleObservation& o) {
  BundlePose b;
  const Mat6 A = se3_adjoint(o.tag.T_bundle_tag);
  b.T_camera_bundle = o.pose.best.T_camera_tag * o.tag.T_bundle_tag.inverse();
  b.covariance = A * o.pose.covariance * A.transpose();
  b.ids = {o.tag.id};
  b.ambiguous = o.pose.ambiguous;
  b.ambiguity_chi2 = o.pose.ambiguity_chi2;
  if (b.ambiguous)
    b.why_degraded = fmt::format("ambiguous: only tag {} in view, and its second pose fits within chi2 {:.1f}",
                                 o.tag.id, b.ambiguity_chi2);
  return b;
}

// Corner-space chi2 between two poses: how well the data tells them apart.
double separation_chi2(const Camera& cam, const CornerSet& tags, const Pose& a, const Pose& b) {
  Eigen::VectorXd ra, rb;
  if (!residuals(cam, tags, a, ra) || !residuals(cam, tags, b, rb)) return std::numeric_limits<double>::infinity();
  return (ra - rb).squaredNorm();  // the measured corners cancel
}

// A tag's own pose against the pose the other tags give it. Its best solution is the one
// compared, or its second when only that one agrees: the others then resolved its flip.
TagAgreement agreement_of(const Camera& cam, const BundleObservation& o, const Fit& others, double limit) {
  const Pose T_predicted = others.T * o.tag.T_bundle_tag;
  const Mat6 A = se3_adjoint(o.tag.T_bundle_tag.inverse());
  const Mat6 C_predicted = A * others.covariance * A.transpose();
  const auto compare = [&](const PoseSolution& s) {
    // The tag's own covariance at this solution, before any ambiguity inflation (which
    // covers the other solution, compared on its own here).
    const Mat6 C_tag =
        pose_covariance(corner_jacobian(cam, s.T_camera_tag, o.tag.size_m), o.pose.corner_covariance);
    const Vec6 e = boxminus(s.T_camera_tag, T_predicted);
    return TagAgreement{o.tag.id, e.dot((C_tag + C_predicted).ldlt().solve(e)),
                        (s.T_camera_tag.translation() - T_predicted.translation()).norm(),
                        so3_log(T_predicted.rotation().transpose() * s.T_camera_tag.rotation()).norm()};
  };
  const TagAgreement best = compare(o.pose.best);
  if (best.chi2 <= limit || !o.pose.second) return best;
  const TagAgreement second = compare(*o.pose.second);
  return second.chi2 <= limit ? second : best;
}

// Gauss-Newton from each start, lowest starting cost first, skipping a start near a
// minimum already found (0.01: 0.6 degrees or 1 cm, far below a flip and far above the
// noise); the fits sorted by cost.
std::vector<Fit> fits_from(const Camera& cam, const CornerSet& tags, const std::vector<Pose>& starts) {
  std::vector<std::pair<double, Pose>> ordered;
  for (const Pose& T : starts) ordered.emplace_back(cost_at(cam, tags, T), T);
  std::sort(ordered.begin(), ordered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Fit> fits;
  for (const auto& [cost, T] : ordered)
    if (std::none_of(fits.begin(), fits.end(), [&](const Fit& f) { return boxminus(T, f.T).norm() < 0.01; }))
      fits.push_back(gauss_newton(cam, tags, T));
  std::sort(fits.begin(), fits.end(), [](const Fit& a, const Fit& b) { return a.cost < b.cost; });
  return fits;
}

// Both solutions of each of these tags, mapped to the bundle.
std::vector<Pose> tag_starts(const std::vector<BundleObservation>& observations, const std::vector<std::size_t>& which) {
  std::vector<Pose> starts;
  for (std::size_t i : which) {
    const BundleObservation& o = observations[i];
    const Pose T_tag_bundle = o.tag.T_bundle_tag.inverse();
    starts.push_back(o.pose.best.T_camera_tag * T_tag_bundle);
    if (o.pose.second) starts.push_back(o.pose.second->T_camera_tag * T_tag_bundle);
  }
  return starts;
}

std::string describe(const TagAgreement& a, double limit) {
  return fmt::format("tag {} is {:.1f} mm and {:.2f} deg from where the other tags put it (chi2 {:.1f} on 6 dof, "
                     "limit {:.1f})",
                     a.id, a.offset_m * 1e3, a.offset_rad * 180 / M_PI, a.chi2, limit);
}

}  // namespace

Result<BundlePose> estimate_bundle_pose(const Camera& cam, const std::vector<BundleObservation>& observations,
                                        double ambiguity_chi2, double consistency_chi2) {
  if (observations.empty()) return fail("no tag of the bundle in view");
  if (observations.size() == 1) return from_one_tag(observations[0]);
  auto corners = corners_of_all(observations);
  if (!corners) return std::unexpected(corners.error());
  const CornerSet& tags = *corners;

  // Starts: both solutions of every tag.
  std::vector<std::size_t> members(observations.size());
  std::iota(members.begin(), members.end(), std::size_t{0});
  const std::vector<Fit> fits = fits_from(cam, tags, tag_starts(observations, members));
  const Fit& best = fits.front();
  if (!std::isfinite(best.cost) || !best.covariance.allFinite())
    return fail("no bundle pose puts its tags in front of the camera");

  BundlePose out;
  std::vector<std::string> why;

  // A second minimum the corners cannot tell from the best: cover it.
  out.ambiguity_chi2 = std::numeric_limits<double>::infinity();
  const Fit* second = nullptr;
  for (std::size_t i = 1; i < fits.size(); ++i) {
    const Vec6 s = boxminus(fits[i].T, best.T);
    if (!std::isfinite(fits[i].cost) || s.dot(best.covariance.ldlt().solve(s)) < 1) continue;  // the same minimum
    const double chi2 = separation_chi2(cam, tags, fits[i].T, best.T);
    if (chi2 < out.ambiguity_chi2) out.ambiguity_chi2 = chi2, second = &fits[i];
  }
  if (second && out.ambiguity_chi2 < ambiguity_chi2) {
    out.ambiguous = true;
    why.push_back(fmt::format("ambiguous: a second pose fits within chi2 {:.1f}", out.ambiguity_chi2));
  }

  // Each tag against the others. While a strict majority of the tags in view would still
  // agree without it, the worst tag above the limit is left out and the rest refitted;
  // when none can be left out (two tags, or no majority), the covariance grows to cover
  // the pose the others give without each disagreeing tag. The tags kept after one is left
  // out are fitted anew from their own solutions as well as from the pose before: a tag
  // far off its place can pull the fit of all into the wrong one of two minima (a
  // board's flip), where the others alone would not be.
  Fit fit = best;
  std::vector<TagAgreement> agreement, left_out;
  std::vector<Fit> without;  // per member: the fit of the other members
  for (;;) {
    agreement.clear(), without.clear();
    for (std::size_t m = 0; m < members.size(); ++m) {
      std::vector<std::size_t> others;
      for (std::size_t k = 0; k < members.size(); ++k)
        if (k != m) others.push_back(members[k]);
      without.push_back(gauss_newton(cam, subset(tags, others), fit.T));
      agreement.push_back(agreement_of(cam, observations[members[m]], without.back(), consistency_chi2));
    }
    const auto worst = static_cast<std::size_t>(
        std::max_element(agreement.begin(), agreement.end(),
                         [](const TagAgreement& a, const TagAgreement& b) { return a.chi2 < b.chi2; }) -
        agreement.begin());
    const bool majority_without_it = members.size() > 2 && 2 * (members.size() - 1) > observations.size();
    if (!(agreement[worst].chi2 > consistency_chi2) || !majority_without_it) break;
    left_out.push_back(agreement[worst]);
    members.erase(members.begin() + static_cast<std::ptrdiff_t>(worst));
    std::vector<Pose> starts = tag_starts(observations, members);
    starts.push_back(without[worst].T);
    fit = fits_from(cam, subset(tags, members), starts).front();
  }
  for (const TagAgreement& a : left_out) why.push_back(fmt::format("left out {}", describe(a, consistency_chi2)));
  out.T_camera_bundle = fit.T;
  out.covariance = fit.covariance;
  std::vector<std::string> disagreeing;
  for (std::size_t m = 0; m < members.size(); ++m) {
    if (!(agreement[m].chi2 > consistency_chi2)) continue;
    const Vec6 d = boxminus(without[m].T, fit.T);
    out.covariance += positive_part(without[m].covariance - fit.covariance) + d * d.transpose();
    disagreeing.push_back(describe(agreement[m], consistency_chi2));
  }
  if (!disagreeing.empty())
    why.push_back(fmt::format("no majority of the tags agrees, so the covariance covers each: {}",
                              fmt::join(disagreeing, "; ")));
  out.disagree = !left_out.empty() || !disagreeing.empty();
  if (out.ambiguous) {
    const Vec6 s = boxminus(second->T, fit.T);
    out.covariance += s * s.transpose();
  }
  for (std::size_t m : members) out.ids.push_back(observations[m].tag.id);
  for (const TagAgreement& a : left_out) out.left_out.push_back(a.id);
  out.agreement = agreement;
  out.agreement.insert(out.agreement.end(), left_out.begin(), left_out.end());
  std::sort(out.agreement.begin(), out.agreement.end(),
            [](const TagAgreement& a, const TagAgreement& b) { return a.chi2 > b.chi2; });
  out.covariance = (out.covariance + out.covariance.transpose()) / 2;
  out.why_degraded = fmt::format("{}", fmt::join(why, "; "));
  return out;
}

Result<BundlePose> refine_bundle_pose(const Camera& cam, const std::vector<BundleObservation>& observations,
                                      const Pose& start) {
  auto corners = corners_of_all(observations);
  if (!corners) return std::unexpected(corners.error());
  const Fit fit = gauss_newton(cam, *corners, start);
  if (!std::isfinite(fit.cost) || !fit.covariance.allFinite()) return fail("no bundle pose near the start fits");
  BundlePose out;
  out.T_camera_bundle = fit.T;
  out.covariance = fit.covariance;
  for (const auto& o : observations) out.ids.push_back(o.tag.id);
  out.ambiguity_chi2 = std::numeric_limits<double>::infinity();
  return out;
}

std::vector<BundleObservation> with_own_scales(std::vector<BundleObservation> observations) {
  for (BundleObservation& o : observations) o.pose.apparent_scale_px.setZero();
  return observations;
}

}  // namespace covtrack::fiducial
