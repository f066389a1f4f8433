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

// A sigma pose as rotation and translation: applying it to a vertex is 9 multiply-adds,
// written out (Eigen's fixed 3x3 products are not inlined at -O2 in this loop).
struct RigidMap {
  double r[9];  // row-major
  double t[3];
  Vec3 operator()(const Vec3& p) const {
    return {r[0] * p.x() + r[1] * p.y() + r[2] * p.z() + t[0],
            r[3] * p.x() + r[4] * p.y() + r[5] * p.z() + t[1],
            r[6] * p.x() + r[7] * p.y() + r[8] * p.z() + t[2]};
  }
};

// The 2n perturbed poses T * Exp(+-sigma_i) and the weights, shared by all vertices.
// Sigma point 0 is the pose itself: its pixel is the vertex's own, projected by the caller.
struct SigmaPoses {
  std::array<RigidMap, 2 * kN> T;
  double wm0, wc0, wi;
};

RigidMap compose(const Mat3& R0, const Vec3& t0, const double (&E)[9], const Vec3& te) {
  RigidMap m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      m.r[3 * i + j] = R0(i, 0) * E[j] + R0(i, 1) * E[3 + j] + R0(i, 2) * E[6 + j];
    m.t[i] = R0(i, 0) * te.x() + R0(i, 1) * te.y() + R0(i, 2) * te.z() + t0[i];
  }
  return m;
}

// T * Exp(xi) and T * Exp(-xi), as pose * se3_exp(+-xi) but with one sin/cos pair for both
// signs and for both the rotation and the left Jacobian (se3_exp evaluates them
// separately; this is the per-object hot path). With K = skew(phi), theta = |phi| and
// K^2 = phi phi^T - theta^2 I:
//   R = (1 - b theta^2) I + b phi phi^T + a K,
//   V rho = (1 - c theta^2) rho + c phi (phi . rho) + b phi x rho,
//   a = sin(theta)/theta, b = (1 - cos(theta))/theta^2, c = (theta - sin(theta))/theta^3.
// Negating xi flips the a K term of R and the terms of V rho that are odd in xi.
void compose_exp_pair(const Mat3& R0, const Vec3& t0, const Vec6& xi, RigidMap& plus,
                      RigidMap& minus) {
  const Vec3 rho = xi.head<3>(), phi = xi.tail<3>();
  const double t2 = phi.squaredNorm();
  double a, b, c;
  if (t2 < 1e-4) {  // theta < 1e-2: series, error below theta^6/5040 (c would cancel)
    a = 1 - t2 / 6 * (1 - t2 / 20);
    b = 0.5 - t2 / 24 * (1 - t2 / 30);
    c = 1.0 / 6 - t2 / 120 * (1 - t2 / 42);
  } else {
    const double theta = std::sqrt(t2), inv = 1 / theta;
    const double sn = std::sin(theta), cs = std::cos(theta);
    a = sn * inv;
    b = (1 - cs) * inv * inv;
    c = (theta - sn) * inv * inv * inv;
  }
  const double x = phi.x(), y = phi.y(), z = phi.z(), d = 1 - b * t2;
  const double ax = a * x, ay = a * y, az = a * z;
  const double bxy = b * x * y, bxz = b * x * z, byz = b * y * z;
  const double Ep[9] = {d + b * x * x, bxy - az, bxz + ay,
                        bxy + az, d + b * y * y, byz - ax,
                        bxz - ay, byz + ax, d + b * z * z};
  const double Em[9] = {Ep[0], bxy + az, bxz - ay,
                        bxy - az, Ep[4], byz + ax,
                        bxz + ay, byz - ax, Ep[8]};
  const Vec3 odd = (1 - c * t2) * rho + c * phi.dot(rho) * phi;
  const Vec3 even = b * phi.cross(rho);
  plus = compose(R0, t0, Ep, even + odd);
  minus = compose(R0, t0, Em, even - odd);
}

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
  const Mat3 R = pose.T.linear();
  const Vec3 t = pose.T.translation();
  SigmaPoses s;
  for (int i = 0; i < kN; ++i) compose_exp_pair(R, t, S.col(i), s.T[i], s.T[kN + i]);
  s.wm0 = lambda / (kN + lambda);
  s.wc0 = s.wm0 + (1 - ut.alpha * ut.alpha + ut.beta);
  s.wi = 0.5 / (kN + lambda);
  return s;
}

bool rotation_too_uncertain(const Mat6& C, double max_sigma_rad) {
  const Eigen::Matrix3d Crot = C.bottomRightCorner<3, 3>();
  // The largest eigenvalue of a PSD matrix is at most its trace: the usual case needs no
  // eigenvalues (the closed form costs an acos and a cos per object).
  if (Crot.trace() <= max_sigma_rad * max_sigma_rad) return false;
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

// `v` holds the unperturbed vertex's pixel (sigma point 0: the pose itself).
void project_unscented(const Camera& camera, const SigmaPoses& s, const Vec3& p,
                       const ProjectionOptions& o, ProjectedVertex& v) {
  std::array<Vec2, kSigmaPoints> px;
  px[0] = v.mean_px;
  for (int i = 1; i < kSigmaPoints; ++i) {
    const Vec3 pc = s.T[i - 1](p);
    if (pc.z() < o.near_m) {
      v.flags.sigma_point_behind_camera = true;
      return;  // a pixel from behind the camera would poison the sums
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
}

}  // namespace

void project_vertices(const Camera& camera, const UncertainPose& pose,
                      std::span<const Vec3> points, const ProjectionOptions& o,
                      std::vector<ProjectedVertex>& out) {
  out.clear();
  // An unbounded pose has no covariance to transform (it may hold infinities).
  const bool use_covariance = !pose.unbounded;
  const bool rot_flag =
      use_covariance && rotation_too_uncertain(pose.covariance, o.max_rotation_sigma_rad);
  const bool unscented = o.method == ProjectionMethod::unscented && use_covariance;
  SigmaPoses sigma;
  if (unscented) sigma = make_sigma_poses(pose, o.unscented);

  for (const Vec3& p : points) {
    ProjectedVertex& v = out.emplace_back();
    const Vec3 pc = pose.T * p;
    v.depth_m = pc.z();
    v.flags.unbounded = pose.unbounded;
    v.flags.rotation_too_uncertain = rot_flag;
    if (pc.z() < o.near_m) {
      v.flags.behind_camera = true;
      continue;
    }
    v.mean_px = camera.project(pc);
    if (unscented) {
      project_unscented(camera, sigma, p, o, v);
    } else if (use_covariance) {
      const Mat26 J = pixel_jacobian_wrt_perturbation(camera, pose.T, p);
      v.covariance_px2 = J * pose.covariance * J.transpose();
    }
    if (o.add_intrinsic_uncertainty && v.flags.usable())
      v.covariance_px2 += camera.intrinsic_covariance(pc);
  }
}

std::vector<ProjectedVertex> project_vertices(const Camera& camera, const UncertainPose& pose,
                                              std::span<const Vec3> points,
                                              const ProjectionOptions& o) {
  std::vector<ProjectedVertex> out;
  out.reserve(points.size());
  project_vertices(camera, pose, points, o, out);
  return out;
}

ProjectedVertex project_vertex(const Camera& camera, const UncertainPose& pose,
                               const Vec3& p, const ProjectionOptions& o) {
  return project_vertices(camera, pose, std::span<const Vec3>(&p, 1), o).front();
}

}  // namespace covtrack::client
