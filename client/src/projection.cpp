#include "covtrack/client/projection.hpp"

#include <array>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace covtrack::client {

ProjectionFlags& ProjectionFlags::operator|=(const ProjectionFlags& o) {
  behind_camera |= o.behind_camera;
  sigma_point_behind_camera |= o.sigma_point_behind_camera;
  rotation_too_uncertain |= o.rotation_too_uncertain;
  unbounded |= o.unbounded;
  covariance_repaired |= o.covariance_repaired;
  return *this;
}

Mat26 pixel_jacobian_wrt_perturbation(const Camera& camera, const Pose& T, const Vec3& p) {
  // T Exp(xi) p ~ T (p + rho + phi x p) = T p + R (rho - skew(p) phi).
  Mat23 J_cam;
  camera.project(T * p, &J_cam);
  const Mat23 JR = J_cam * T.linear();
  Mat26 J;
  J << JR, -JR * skew(p);
  return J;
}

namespace {

constexpr int kN = 6;
constexpr int kSigmaPoints = 2 * kN + 1;

// The 2n+1 perturbed poses T * Exp(sigma_i) and their weights, shared by all vertices.
struct SigmaPoses {
  std::array<Pose, kSigmaPoints> T;
  double wm0, wc0, wi;
};

SigmaPoses make_sigma_poses(const UncertainPose& pose, const UnscentedParams& ut) {
  const double lambda = ut.alpha * ut.alpha * (kN + ut.kappa) - kN;
  const Mat6 scaled = (kN + lambda) * pose.covariance;
  // Cholesky is the cheap square root; a singular covariance (a degree of freedom known
  // exactly) needs the eigen decomposition.
  Mat6 S;
  Eigen::LLT<Mat6> llt(scaled);
  if (llt.info() == Eigen::Success) {
    S = llt.matrixL();
  } else {
    Eigen::SelfAdjointEigenSolver<Mat6> eig(scaled);
    S = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  }
  SigmaPoses s;
  s.T[0] = pose.T;
  for (int i = 0; i < kN; ++i) {
    s.T[1 + i] = pose.T * se3_exp(S.col(i));
    s.T[1 + kN + i] = pose.T * se3_exp(-S.col(i));
  }
  s.wm0 = lambda / (kN + lambda);
  s.wc0 = s.wm0 + (1 - ut.alpha * ut.alpha + ut.beta);
  s.wi = 0.5 / (kN + lambda);
  return s;
}

bool rotation_too_uncertain(const Mat6& C, double max_sigma_rad) {
  const Eigen::Matrix3d Crot = C.bottomRightCorner<3, 3>();
  // Largest eigenvalue of a 3x3 symmetric matrix, closed form (cheap, per object).
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>()
                             .computeDirect(Crot, Eigen::EigenvaluesOnly)
                             .eigenvalues()
                             .maxCoeff();
  return std::sqrt(std::max(largest, 0.0)) > max_sigma_rad;
}

// The UT with a negative centre weight (kappa = 3 - n) can give an indefinite matrix.
Mat2 repair_psd(const Mat2& C, bool& repaired) {
  const double tr = C.trace(), det = C.determinant();
  if (tr >= 0 && det >= 0) return C;
  repaired = true;
  Eigen::SelfAdjointEigenSolver<Mat2> eig(C);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
         eig.eigenvectors().transpose();
}

ProjectedVertex project_unscented(const Camera& camera, const SigmaPoses& s,
                                  const Vec3& p, const ProjectionOptions& o,
                                  ProjectedVertex v) {
  std::array<Vec2, kSigmaPoints> px;
  for (int i = 0; i < kSigmaPoints; ++i) {
    const Vec3 pc = s.T[i] * p;
    if (pc.z() < o.near_m) {
      v.flags.sigma_point_behind_camera = true;
      return v;  // a pixel from behind the camera would poison the sums
    }
    px[i] = camera.project(pc);
  }
  Vec2 mean = s.wm0 * px[0];
  for (int i = 1; i < kSigmaPoints; ++i) mean += s.wi * px[i];
  Vec2 d = px[0] - mean;
  Mat2 cov = s.wc0 * d * d.transpose();
  for (int i = 1; i < kSigmaPoints; ++i) {
    d = px[i] - mean;
    cov += s.wi * d * d.transpose();
  }
  v.mean_px = mean;
  v.covariance_px2 = repair_psd(cov, v.flags.covariance_repaired);
  return v;
}

// Everything but the pose-uncertainty part, shared by both methods.
ProjectedVertex start_vertex(const Camera& camera, const UncertainPose& pose, const Vec3& p,
                             const ProjectionOptions& o, bool rotation_flag) {
  ProjectedVertex v;
  const Vec3 pc = pose.T * p;
  v.depth_m = pc.z();
  v.flags.unbounded = pose.unbounded;
  v.flags.rotation_too_uncertain = rotation_flag;
  if (pc.z() < o.near_m) {
    v.flags.behind_camera = true;
    return v;
  }
  v.mean_px = camera.project(pc);
  return v;
}

void finish_vertex(const Camera& camera, const Vec3& pc, const ProjectionOptions& o,
                   ProjectedVertex& v) {
  if (o.add_intrinsic_uncertainty && v.flags.usable())
    v.covariance_px2 += camera.intrinsic_covariance(pc);
}

}  // namespace

std::vector<ProjectedVertex> project_vertices(const Camera& camera, const UncertainPose& pose,
                                              std::span<const Vec3> points,
                                              const ProjectionOptions& o) {
  std::vector<ProjectedVertex> out;
  out.reserve(points.size());
  // An unbounded pose has no covariance to transform (it may hold infinities).
  const bool use_covariance = !pose.unbounded;
  const bool rot_flag =
      use_covariance && rotation_too_uncertain(pose.covariance, o.max_rotation_sigma_rad);
  const bool unscented = o.method == ProjectionMethod::unscented && use_covariance;
  SigmaPoses sigma;
  if (unscented) sigma = make_sigma_poses(pose, o.unscented);

  for (const Vec3& p : points) {
    ProjectedVertex v = start_vertex(camera, pose, p, o, rot_flag);
    if (!v.flags.behind_camera && use_covariance) {
      if (unscented) {
        v = project_unscented(camera, sigma, p, o, v);
      } else {
        const Mat26 J = pixel_jacobian_wrt_perturbation(camera, pose.T, p);
        v.covariance_px2 = J * pose.covariance * J.transpose();
      }
    }
    finish_vertex(camera, pose.T * p, o, v);
    out.push_back(v);
  }
  return out;
}

ProjectedVertex project_vertex(const Camera& camera, const UncertainPose& pose,
                               const Vec3& p, const ProjectionOptions& o) {
  return project_vertices(camera, pose, std::span<const Vec3>(&p, 1), o).front();
}

}  // namespace covtrack::client
