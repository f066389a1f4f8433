#include "covtrack/client/projection.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "vector_clones.hpp"

namespace covtrack::client {

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

// The 2n+1 sigma poses T * Exp(+-sigma_i), pose 0 = T, and the weights, shared by all
// vertices. Structure-of-arrays: element e of pose i (rotation row-major, then translation)
// is pose[e][i], so that they are written and read as whole vectors, not transposed.
struct SigmaPoses {
  double pose[12][kSigmaPoints];
  double wm0, wc0, wi;
};

// The columns xi_i = (rho, phi) of a square root S of the scaled covariance, component r
// of column i at [r][i]: whole vectors of kLanes (the n = 6 columns and two zero columns).
constexpr int kLanes = 8;
using SigmaColumns = double[kN][kLanes];

// The 2n sigma poses T * Exp(+-xi_i) for the columns xi_i = (rho, phi) of S, as
// pose * se3_exp(+-xi) but all columns at once in loops that vectorise (vector_clones.hpp),
// with one (a, b, c) per column for both signs and for both the rotation and the left
// Jacobian. With K = skew(phi), theta = |phi| and K^2 = phi phi^T - theta^2 I:
//   R = (1 - b theta^2) I + b phi phi^T + a K,
//   V rho = (1 - c theta^2) rho + c phi (phi . rho) + b phi x rho,
//   a = sin(theta)/theta, b = (1 - cos(theta))/theta^2, c = (theta - sin(theta))/theta^3.
// Negating xi flips the a K term of R and the terms of V rho that are odd in xi.
// Writes pose 1 + i = T Exp(xi_i) and pose 1 + n + i = T Exp(-xi_i).
COVTRACK_VECTOR_CLONES
void exp_sigma_poses(const Mat3& R0, const Vec3& t0, const SigmaColumns& S, double (&out)[12][kSigmaPoints]) {
  const double *rx = S[0], *ry = S[1], *rz = S[2], *px = S[3], *py = S[4], *pz = S[5];
  double t2[kLanes], a[kLanes], b[kLanes], c[kLanes];
  for (int i = 0; i < kLanes; ++i) {
    // theta < 0.3 rad (sigma points of rotation sigmas up to 10 degrees): the Taylor series
    // to theta^10, in Horner form with constant coefficients (no divisions). The next terms
    // are below 1e-16: as exact as sin and cos, and no cancellation in c. Coefficients:
    // (-1)^k / (2k+1)!, / (2k+2)!, / (2k+3)!. Larger angles are redone below.
    const double t = t2[i] = px[i] * px[i] + py[i] * py[i] + pz[i] * pz[i];
    a[i] = 1 + t * (-1 / 6. + t * (1 / 120. + t * (-1 / 5040. + t * (1 / 362880. + t * (-1 / 39916800.)))));
    b[i] = 1 / 2. + t * (-1 / 24. + t * (1 / 720. + t * (-1 / 40320. + t * (1 / 3628800. + t * (-1 / 479001600.)))));
    c[i] = 1 / 6. + t * (-1 / 120. + t * (1 / 5040. + t * (-1 / 362880. + t * (1 / 39916800. + t * (-1 / 6227020800.)))));
  }
  for (int i = 0; i < kN; ++i)
    if (t2[i] >= 0.09) {
      const double theta = std::sqrt(t2[i]), inv = 1 / theta;
      const double sn = std::sin(theta), cs = std::cos(theta);
      a[i] = sn * inv;
      b[i] = (1 - cs) * inv * inv;
      c[i] = (theta - sn) * inv * inv * inv;
    }
  // Rotation and translation of both signs, composed with T: row-major 3x3 then 3.
  double plus[12][kLanes], minus[12][kLanes];
  for (int i = 0; i < kLanes; ++i) {
    const double x = px[i], y = py[i], z = pz[i], d = 1 - b[i] * t2[i];
    const double ax = a[i] * x, ay = a[i] * y, az = a[i] * z;
    const double bxy = b[i] * x * y, bxz = b[i] * x * z, byz = b[i] * y * z;
    const double Ep[9] = {d + b[i] * x * x, bxy - az, bxz + ay,
                          bxy + az, d + b[i] * y * y, byz - ax,
                          bxz - ay, byz + ax, d + b[i] * z * z};
    const double Em[9] = {Ep[0], bxy + az, bxz - ay,
                          bxy - az, Ep[4], byz + ax,
                          bxz + ay, byz - ax, Ep[8]};
    const double dot = x * rx[i] + y * ry[i] + z * rz[i], lin = 1 - c[i] * t2[i];
    const double odd[3] = {lin * rx[i] + c[i] * dot * x, lin * ry[i] + c[i] * dot * y, lin * rz[i] + c[i] * dot * z};
    const double even[3] = {b[i] * (y * rz[i] - z * ry[i]), b[i] * (z * rx[i] - x * rz[i]), b[i] * (x * ry[i] - y * rx[i])};
    // Unrolled, so that the loop over the lanes is the only loop left to vectorise.
#pragma GCC unroll 3
    for (int r = 0; r < 3; ++r) {
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k) {
        plus[3 * r + k][i] = R0(r, 0) * Ep[k] + R0(r, 1) * Ep[3 + k] + R0(r, 2) * Ep[6 + k];
        minus[3 * r + k][i] = R0(r, 0) * Em[k] + R0(r, 1) * Em[3 + k] + R0(r, 2) * Em[6 + k];
      }
      plus[9 + r][i] = R0(r, 0) * (even[0] + odd[0]) + R0(r, 1) * (even[1] + odd[1]) + R0(r, 2) * (even[2] + odd[2]) + t0[r];
      minus[9 + r][i] = R0(r, 0) * (even[0] - odd[0]) + R0(r, 1) * (even[1] - odd[1]) + R0(r, 2) * (even[2] - odd[2]) + t0[r];
    }
  }
  for (int e = 0; e < 12; ++e)
    for (int i = 0; i < kN; ++i) out[e][1 + i] = plus[e][i], out[e][1 + kN + i] = minus[e][i];
}

// A square root S (S S^T = scale A) of a positive definite A, from A = L D L^T (L unit lower
// triangular): S = L sqrt(scale D), the Cholesky factor. Each column's pivot waits only on
// one division of the previous columns, not on a square root and a division as in the
// Cholesky factor itself; the six square roots come at the end, side by side. False where
// a pivot is not positive (or not a number). Written out: Eigen's general LLT took twice as
// long on a 6x6, and there is one per object per frame.
bool scaled_square_root6(const Mat6& A, double scale, SigmaColumns& S) {
  double L[6][6], E[6][6], d[6];  // E = L D: column j of L times d_j
  for (int j = 0; j < 6; ++j) {
    double pivot = A(j, j);
    for (int k = 0; k < j; ++k) pivot -= E[j][k] * L[j][k];
    if (!(pivot > 0)) return false;
    d[j] = pivot;
    const double inverse = 1 / pivot;
    for (int i = j + 1; i < 6; ++i) {
      double v = A(i, j);
      for (int k = 0; k < j; ++k) v -= E[i][k] * L[j][k];
      E[i][j] = v;
      L[i][j] = v * inverse;
    }
  }
  double root[6];
  for (int j = 0; j < 6; ++j) root[j] = std::sqrt(scale * d[j]);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < kLanes; ++j) S[i][j] = j > i ? 0.0 : i == j ? root[j] : L[i][j] * root[j];
  return true;
}

// Pose 0 of a structure-of-arrays set: the unperturbed pose (rotation row-major, then translation).
template <int Points>
void write_unperturbed_pose(const Mat3& R, const Vec3& t, double (&pose)[12][Points]) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) pose[3 * i + j][0] = R(i, j);
    pose[9 + i][0] = t[i];
  }
}

SigmaPoses make_sigma_poses(const UncertainPose& pose, const UnscentedParams& ut) {
  const double lambda = ut.alpha * ut.alpha * (kN + ut.kappa) - kN;
  // The default is the Cholesky root (projection.hpp says why). The symmetric and the
  // principal roots come from the eigen decomposition; so does a Cholesky root of a
  // singular covariance (a degree of freedom known exactly).
  const SigmaRoot kind = ut.root == SigmaRoot::automatic ? SigmaRoot::cholesky : ut.root;
  SigmaColumns S;
  if (kind != SigmaRoot::cholesky || !scaled_square_root6(pose.covariance, kN + lambda, S)) {
    Eigen::SelfAdjointEigenSolver<Mat6> eig((kN + lambda) * pose.covariance);
    Mat6 root = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    if (kind == SigmaRoot::symmetric) root = root * eig.eigenvectors().transpose();
    for (int i = 0; i < kN; ++i)
      for (int j = 0; j < kLanes; ++j) S[i][j] = j < kN ? root(i, j) : 0.0;
  }
  const Mat3 R = pose.T.linear();
  const Vec3 t = pose.T.translation();
  SigmaPoses s;
  write_unperturbed_pose(R, t, s.pose);
  exp_sigma_poses(R, t, S, s.pose);
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

// A UT with a negative centre weight (kappa < 0, e.g. the plain 3 - n) can give an
// indefinite matrix; the default (kappa 0) cannot, beyond rounding.
Mat2 repair_psd(const Mat2& C, bool& repaired) {
  const double tr = C.trace(), det = C.determinant();
  if (tr >= 0 && det >= 0) return C;
  Eigen::SelfAdjointEigenSolver<Mat2> eig(C);
  // A negative eigenvalue within rounding of the sums (a pose known exactly, or nearly:
  // every sigma point on the same pixel) is clipped without a flag; only a real one,
  // from the negative centre weight on a bending map, is reported.
  constexpr double kRoundingPx2 = 1e-12, kRoundingRelative = 1e-9;
  const double scale = eig.eigenvalues().cwiseAbs().maxCoeff();
  repaired = repaired || eig.eigenvalues().minCoeff() < -std::max(kRoundingPx2, kRoundingRelative * scale);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
         eig.eigenvectors().transpose();
}

// Vertices go through the unscented transform in blocks: every sigma point of kBlock
// vertices in loops of fixed length over structure-of-arrays data, which vectorise
// (vector_clones.hpp). A short last block repeats its first vertex.
constexpr int kBlock = 8;

struct UnscentedBlock {
  double u0[kBlock], v0[kBlock];  // pixel of the unperturbed vertex (sigma point 0)
  double z0[kBlock];              // its camera depth
  double zmin[kBlock];            // the nearest depth over all sigma points
  double r2max[kBlock];           // the largest normalised radius^2 over all sigma points
  double zvar[kBlock];            // the depth's variance over the sigma points
  double mean_u[kBlock], mean_v[kBlock];
  double cuu[kBlock], cuv[kBlock], cvv[kBlock];
};

COVTRACK_VECTOR_CLONES
void unscented_block(const Camera& camera, const SigmaPoses& s, const double (&px)[kBlock],
                     const double (&py)[kBlock], const double (&pz)[kBlock], UnscentedBlock& out) {
  // Local copies: the compiler need not fear that a store through `out` changes them.
  const Camera cam = camera;
  const double wm0 = s.wm0, wc0 = s.wc0, wi = s.wi;
  double u[kSigmaPoints][kBlock], v[kSigmaPoints][kBlock], zmin[kBlock], z0[kBlock], r2max[kBlock];
  double dz1[kBlock], dz2[kBlock];  // sums of the sigma points' depths less z0, and of their squares
  for (int j = 0; j < kBlock; ++j) {
    const auto& m = s.pose;
    z0[j] = zmin[j] = m[6][0] * px[j] + m[7][0] * py[j] + m[8][0] * pz[j] + m[11][0];
    r2max[j] = 0, dz1[j] = 0, dz2[j] = 0;
  }
  for (int i = 0; i < kSigmaPoints; ++i) {
    double m[12];  // pose i
    for (int e = 0; e < 12; ++e) m[e] = s.pose[e][i];
    for (int j = 0; j < kBlock; ++j) {
      const double x = m[0] * px[j] + m[1] * py[j] + m[2] * pz[j] + m[9];
      const double y = m[3] * px[j] + m[4] * py[j] + m[5] * pz[j] + m[10];
      const double z = m[6] * px[j] + m[7] * py[j] + m[8] * pz[j] + m[11];
      // A point behind the camera gives a meaningless pixel here; the caller checks zmin.
      const double iz = 1 / z, xn = x * iz, yn = y * iz;
      cam.pixel_of_normalised(xn, yn, u[i][j], v[i][j]);
      const double dz = i > 0 ? z - z0[j] : 0.0;
      dz1[j] += dz, dz2[j] += dz * dz;
      zmin[j] = std::min(zmin[j], z);
      r2max[j] = std::max(r2max[j], xn * xn + yn * yn);
    }
  }
  double mu[kBlock], mv[kBlock], cuu[kBlock], cuv[kBlock], cvv[kBlock];
  for (int j = 0; j < kBlock; ++j) mu[j] = wm0 * u[0][j], mv[j] = wm0 * v[0][j];
  for (int i = 1; i < kSigmaPoints; ++i)
    for (int j = 0; j < kBlock; ++j) mu[j] += wi * u[i][j], mv[j] += wi * v[i][j];
  for (int j = 0; j < kBlock; ++j) {
    const double du = u[0][j] - mu[j], dv = v[0][j] - mv[j];
    cuu[j] = wc0 * du * du, cuv[j] = wc0 * du * dv, cvv[j] = wc0 * dv * dv;
  }
  for (int i = 1; i < kSigmaPoints; ++i)
    for (int j = 0; j < kBlock; ++j) {
      const double du = u[i][j] - mu[j], dv = v[i][j] - mv[j];
      cuu[j] += wi * du * du, cuv[j] += wi * du * dv, cvv[j] += wi * dv * dv;
    }
  for (int j = 0; j < kBlock; ++j) {
    out.u0[j] = u[0][j], out.v0[j] = v[0][j], out.z0[j] = z0[j], out.zmin[j] = zmin[j], out.r2max[j] = r2max[j];
    // The depth's variance about its mean (z0 + wi dz1; the centre's deviation, 0, has wc0).
    const double mean_dz = wi * dz1[j];
    out.zvar[j] = wi * dz2[j] - 2 * wi * dz1[j] * mean_dz + (2 * kN * wi) * mean_dz * mean_dz + wc0 * mean_dz * mean_dz;
    out.mean_u[j] = mu[j], out.mean_v[j] = mv[j];
    out.cuu[j] = cuu[j], out.cuv[j] = cuv[j], out.cvv[j] = cvv[j];
  }
}

// The first-order path in the same blocks: per vertex J = J_camera R [I, -skew(p)]
// (pixel_jacobian_wrt_perturbation) and J C J^T, written out over the block's lanes.
struct LinearBlock {
  double u[kBlock], v[kBlock], z[kBlock], r2[kBlock], zvar[kBlock];
  double cuu[kBlock], cuv[kBlock], cvv[kBlock];
};

COVTRACK_VECTOR_CLONES
void linear_block(const Camera& camera, const Pose& T, const Mat6& covariance,
                  const double (&px)[kBlock], const double (&py)[kBlock],
                  const double (&pz)[kBlock], LinearBlock& out) {
  const Camera cam = camera;  // local copies: stores through `out` cannot change them
  double R[9], t[3];
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) R[3 * r + k] = T.linear()(r, k);
    t[r] = T.translation()[r];
  }
  // The covariance's blocks for xi = (rho, phi), symmetrised: translation tt (upper
  // triangle: 00 01 02 11 12 22), rotation rr (the same), and translation by rotation tr.
  // Six numbers each, not nine: each is a vector register in the loop below, and with
  // full 3x3 blocks the first-order frame ran 1-3% slower (bench_regions, 12 rounds).
  double tt[6], rr[6], tr[3][3];
  constexpr int kUpper[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int e = 0; e < 6; ++e) {
    const int a = kUpper[e][0], b = kUpper[e][1];
    tt[e] = 0.5 * (covariance(a, b) + covariance(b, a));
    rr[e] = 0.5 * (covariance(3 + a, 3 + b) + covariance(3 + b, 3 + a));
  }
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) tr[a][b] = 0.5 * (covariance(a, 3 + b) + covariance(3 + b, a));
  for (int j = 0; j < kBlock; ++j) {
    const double x = R[0] * px[j] + R[1] * py[j] + R[2] * pz[j] + t[0];
    const double y = R[3] * px[j] + R[4] * py[j] + R[5] * pz[j] + t[1];
    const double z = R[6] * px[j] + R[7] * py[j] + R[8] * pz[j] + t[2];
    const double iz = 1 / z, xn = x * iz, yn = y * iz;
    double d[4], u, v;
    cam.pixel_of_normalised(xn, yn, u, v, d);
    // The point's covariance in the object frame, P = G C G^T for G = [I, -K], K = skew(p)
    // (3x3, then the pixel's rows against it: about 100 products per vertex, where the
    // 2x6 Jacobian against C took 170): P = tt + tr K + (tr K)^T + K^T rr K, as K^T = -K.
    // Row a of tr K is (row a of tr) x p; K^T (rr K) = -K (rr K) has as its columns
    // (rr K)'s crossed with p again.
    const double p[3] = {px[j], py[j], pz[j]};
    const auto cross_p = [&](const double (&w)[3], double (&out3)[3]) {
      out3[0] = w[1] * p[2] - w[2] * p[1], out3[1] = w[2] * p[0] - w[0] * p[2], out3[2] = w[0] * p[1] - w[1] * p[0];
    };
    double trK[3][3], rrK[3][3];  // rows: tr_a x p and rr_a x p (= (rr K)_a)
    const double rr_rows[3][3] = {{rr[0], rr[1], rr[2]}, {rr[1], rr[3], rr[4]}, {rr[2], rr[4], rr[5]}};
#pragma GCC unroll 3
    for (int a = 0; a < 3; ++a) cross_p(tr[a], trK[a]), cross_p(rr_rows[a], rrK[a]);
    // K^T (rr K) = -K (rr K): column b is (column b of rr K) x p.
    const double col0[3] = {rrK[0][0], rrK[1][0], rrK[2][0]}, col1[3] = {rrK[0][1], rrK[1][1], rrK[2][1]},
                 col2[3] = {rrK[0][2], rrK[1][2], rrK[2][2]};
    double k0[3], k1[3], k2[3];
    cross_p(col0, k0), cross_p(col1, k1), cross_p(col2, k2);
    const double P00 = tt[0] + 2 * trK[0][0] + k0[0], P01 = tt[1] + trK[0][1] + trK[1][0] + k1[0],
                 P02 = tt[2] + trK[0][2] + trK[2][0] + k2[0], P11 = tt[3] + 2 * trK[1][1] + k1[1],
                 P12 = tt[4] + trK[1][2] + trK[2][1] + k2[1], P22 = tt[5] + 2 * trK[2][2] + k2[2];
    // d(pixel)/d(camera point) = d(pixel)/d(xn, yn) [iz 0 -xn iz; 0 iz -yn iz], times R:
    // rows w0, w1 of the pixel's derivative by the object-frame point; the depth's is R's
    // third row.
    const double c[2][3] = {{d[0] * iz, d[1] * iz, -(d[0] * xn + d[1] * yn) * iz},
                            {d[2] * iz, d[3] * iz, -(d[2] * xn + d[3] * yn) * iz}};
    double w[3][3];
#pragma GCC unroll 2
    for (int r = 0; r < 2; ++r)
#pragma GCC unroll 3
      for (int k = 0; k < 3; ++k) w[r][k] = c[r][0] * R[k] + c[r][1] * R[3 + k] + c[r][2] * R[6 + k];
    w[2][0] = R[6], w[2][1] = R[7], w[2][2] = R[8];
    double Pw[3][3];
#pragma GCC unroll 3
    for (int r = 0; r < 3; ++r) {
      Pw[r][0] = P00 * w[r][0] + P01 * w[r][1] + P02 * w[r][2];
      Pw[r][1] = P01 * w[r][0] + P11 * w[r][1] + P12 * w[r][2];
      Pw[r][2] = P02 * w[r][0] + P12 * w[r][1] + P22 * w[r][2];
    }
    const auto dot3 = [](const double (&a)[3], const double (&b)[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    out.zvar[j] = dot3(w[2], Pw[2]);
    out.u[j] = u, out.v[j] = v, out.z[j] = z, out.r2[j] = xn * xn + yn * yn;
    out.cuu[j] = dot3(w[0], Pw[0]), out.cuv[j] = dot3(w[0], Pw[1]), out.cvv[j] = dot3(w[1], Pw[1]);
  }
}

// Strongly rotated poses (above UnscentedParams::cubature_min_rotation_trace_rad2) take
// the fifth-degree cubature rule for a Gaussian (McNamee and Stenger): the centre, +-sqrt(3)
// along each column of a square root of the covariance, and +-sqrt(3) along both columns of
// every pair: 2n^2 + 1 = 73 points, exact for every moment of the perturbation up to degree
// five where the unscented transform's 13 are exact to degree three. The pixel's covariance
// then holds every product of two second-order terms (rotation about two axes at once),
// which the unscented transform misses and which is most of its error at 10 degrees.
// Weights 2/3 (centre), (4 - n)/18 = -1/9 (axes), 1/36 (pairs); the negative ones can make
// the covariance indefinite on a map that bends hard, which repair_psd reports. It costs
// about six times the unscented transform per object (bench_regions, EightDegrees).
constexpr int kCubaturePoints = 2 * kN * kN + 1;

// Structure-of-arrays as SigmaPoses: element e of pose i at pose[e][i]; pose 0 unperturbed.
struct CubaturePoses {
  double pose[12][kCubaturePoints];
  double w[kCubaturePoints];
};

// The poses T Exp(xi) of the points, through exp_sigma_poses six columns at a time (each
// call gives +-column): first the axes, then c_i + c_j and c_i - c_j of every pair.
CubaturePoses make_cubature_poses(const UncertainPose& pose) {
  Eigen::SelfAdjointEigenSolver<Mat6> eig(pose.covariance);
  const Mat6 root = std::sqrt(3.0) * eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() *
                    eig.eigenvectors().transpose();
  std::vector<Vec6> columns;
  columns.reserve(kN + kN * (kN - 1));
  for (int i = 0; i < kN; ++i) columns.push_back(root.col(i));
  for (int i = 0; i < kN; ++i)
    for (int j = i + 1; j < kN; ++j) columns.push_back(root.col(i) + root.col(j)), columns.push_back(root.col(i) - root.col(j));
  const Mat3 R = pose.T.linear();
  const Vec3 t = pose.T.translation();
  CubaturePoses c;
  write_unperturbed_pose(R, t, c.pose);
  c.w[0] = 1 + (kN * kN - 7.0 * kN) / 18;
  for (std::size_t first = 0; first < columns.size(); first += kN) {
    SigmaColumns S;
    for (int r = 0; r < kN; ++r)
      for (int l = 0; l < kLanes; ++l) S[r][l] = l < kN ? columns[first + l][r] : 0.0;
    double poses[12][kSigmaPoints];
    exp_sigma_poses(R, t, S, poses);
    for (int k = 1; k < kSigmaPoints; ++k) {
      for (int e = 0; e < 12; ++e) c.pose[e][first * 2 + k] = poses[e][k];
      c.w[first * 2 + k] = first == 0 ? (4.0 - kN) / 18 : 1.0 / 36;
    }
  }
  return c;
}

// What unscented_block gives, through the cubature points (each weighted by its own w).
COVTRACK_VECTOR_CLONES
void cubature_block(const Camera& camera, const CubaturePoses& c, const double (&px)[kBlock],
                    const double (&py)[kBlock], const double (&pz)[kBlock], UnscentedBlock& out) {
  const Camera cam = camera;
  double u[kCubaturePoints][kBlock], v[kCubaturePoints][kBlock], z[kCubaturePoints][kBlock];
  double mu[kBlock] = {}, mv[kBlock] = {}, mz[kBlock] = {}, zmin[kBlock], r2max[kBlock] = {};
  for (int j = 0; j < kBlock; ++j) zmin[j] = INFINITY;
  for (int i = 0; i < kCubaturePoints; ++i) {
    double m[12];
    for (int e = 0; e < 12; ++e) m[e] = c.pose[e][i];
    const double w = c.w[i];
    for (int j = 0; j < kBlock; ++j) {
      const double x = m[0] * px[j] + m[1] * py[j] + m[2] * pz[j] + m[9];
      const double y = m[3] * px[j] + m[4] * py[j] + m[5] * pz[j] + m[10];
      const double zz = z[i][j] = m[6] * px[j] + m[7] * py[j] + m[8] * pz[j] + m[11];
      const double iz = 1 / zz, xn = x * iz, yn = y * iz;
      cam.pixel_of_normalised(xn, yn, u[i][j], v[i][j]);
      mu[j] += w * u[i][j], mv[j] += w * v[i][j], mz[j] += w * zz;
      zmin[j] = std::min(zmin[j], zz);
      r2max[j] = std::max(r2max[j], xn * xn + yn * yn);
    }
  }
  double cuu[kBlock] = {}, cuv[kBlock] = {}, cvv[kBlock] = {}, zvar[kBlock] = {};
  for (int i = 0; i < kCubaturePoints; ++i) {
    const double w = c.w[i];
    for (int j = 0; j < kBlock; ++j) {
      const double du = u[i][j] - mu[j], dv = v[i][j] - mv[j], dz = z[i][j] - mz[j];
      cuu[j] += w * du * du, cuv[j] += w * du * dv, cvv[j] += w * dv * dv, zvar[j] += w * dz * dz;
    }
  }
  for (int j = 0; j < kBlock; ++j) {
    out.u0[j] = u[0][j], out.v0[j] = v[0][j], out.z0[j] = z[0][j], out.zmin[j] = zmin[j], out.r2max[j] = r2max[j];
    out.zvar[j] = zvar[j], out.mean_u[j] = mu[j], out.mean_v[j] = mv[j];
    out.cuu[j] = cuu[j], out.cuv[j] = cuv[j], out.cvv[j] = cvv[j];
  }
}

// Block `first` of the points as structure-of-arrays; a short last block repeats its first
// point. Returns how many of the block's lanes are real points.
int load_block(std::span<const Vec3> points, std::size_t first, double (&px)[kBlock],
               double (&py)[kBlock], double (&pz)[kBlock]) {
  const int count = static_cast<int>(std::min<std::size_t>(kBlock, points.size() - first));
  for (int j = 0; j < kBlock; ++j) {
    const Vec3& p = points[first + (j < count ? j : 0)];
    px[j] = p.x(), py[j] = p.y(), pz[j] = p.z();
  }
  return count;
}

// The next output vertex at this depth: flagged behind the camera when it has no pixel.
ProjectedVertex& start_vertex(std::vector<ProjectedVertex>& out, double depth_m,
                              const ProjectionFlags& shared, const ProjectionOptions& o) {
  ProjectedVertex& v = out.emplace_back();
  v.depth_m = depth_m;
  v.flags = shared;
  v.flags.behind_camera = depth_m < o.near_m;
  return v;
}

// The depth's spread, and the flag when it is a large fraction of the depth.
void set_depth_sigma(ProjectedVertex& v, double depth_variance, const ProjectionOptions& o) {
  v.depth_sigma_m = std::sqrt(std::max(depth_variance, 0.0));
  v.flags.depth_nonlinear = v.depth_sigma_m > o.max_depth_sigma_ratio * v.depth_m;
}

void project_linear(const Camera& camera, const UncertainPose& pose,
                    std::span<const Vec3> points, const ProjectionOptions& o,
                    const ProjectionFlags& shared, std::vector<ProjectedVertex>& out) {
  const bool add_intrinsic = o.add_intrinsic_uncertainty && !camera.intrinsic_sigmas_px.isZero();
  const double fold_r2 = camera.distortion_fold_r2();
  LinearBlock b;
  for (std::size_t first = 0; first < points.size(); first += kBlock) {
    double px[kBlock], py[kBlock], pz[kBlock];
    const int count = load_block(points, first, px, py, pz);
    linear_block(camera, pose.T, pose.covariance, px, py, pz, b);
    for (int j = 0; j < count; ++j) {
      ProjectedVertex& v = start_vertex(out, b.z[j], shared, o);
      if (v.flags.behind_camera) continue;
      v.mean_px = Vec2(b.u[j], b.v[j]);
      set_depth_sigma(v, b.zvar[j], o);
      if ((v.flags.past_distortion_fold = b.r2[j] >= fold_r2)) continue;
      // J C J^T is positive semi-definite for a C that is; an indefinite C is repaired and
      // flagged as the unscented transform's result is.
      Mat2 C;
      C << b.cuu[j], b.cuv[j], b.cuv[j], b.cvv[j];
      v.covariance_px2 = repair_psd(C, v.flags.covariance_repaired);
      if (add_intrinsic) v.covariance_px2 += camera.intrinsic_covariance_at(v.mean_px);
    }
  }
}

// The vertices' pixels from the moments that fill_block(px, py, pz, block) gives for each
// block of them: the unscented transform's or the cubature's.
template <class FillBlock>
void project_from_moments(const Camera& camera, std::span<const Vec3> points, const ProjectionOptions& o,
                          const ProjectionFlags& shared, std::vector<ProjectedVertex>& out, FillBlock&& fill_block) {
  const bool add_intrinsic = o.add_intrinsic_uncertainty && !camera.intrinsic_sigmas_px.isZero();
  const double fold_r2 = camera.distortion_fold_r2();
  UnscentedBlock b;
  for (std::size_t first = 0; first < points.size(); first += kBlock) {
    double px[kBlock], py[kBlock], pz[kBlock];
    const int count = load_block(points, first, px, py, pz);
    fill_block(px, py, pz, b);
    for (int j = 0; j < count; ++j) {
      ProjectedVertex& v = start_vertex(out, b.z0[j], shared, o);
      if (v.flags.behind_camera) continue;
      v.mean_px = Vec2(b.u0[j], b.v0[j]);
      set_depth_sigma(v, b.zvar[j], o);
      if (b.zmin[j] < o.near_m) {
        // A pixel from behind the camera would poison the sums: no covariance.
        v.flags.sigma_point_behind_camera = true;
        continue;
      }
      if ((v.flags.past_distortion_fold = b.r2max[j] >= fold_r2)) continue;  // no covariance either
      const Vec2 unperturbed = v.mean_px;
      v.mean_px = Vec2(b.mean_u[j], b.mean_v[j]);
      Mat2 C;
      C << b.cuu[j], b.cuv[j], b.cuv[j], b.cvv[j];
      v.covariance_px2 = repair_psd(C, v.flags.covariance_repaired);
      if (add_intrinsic) v.covariance_px2 += camera.intrinsic_covariance_at(unperturbed);
    }
  }
}

void project_unscented(const Camera& camera, const UncertainPose& pose,
                       std::span<const Vec3> points, const ProjectionOptions& o,
                       const ProjectionFlags& shared, std::vector<ProjectedVertex>& out) {
  if (pose.covariance.bottomRightCorner<3, 3>().trace() > o.unscented.cubature_min_rotation_trace_rad2) {
    const CubaturePoses c = make_cubature_poses(pose);
    return project_from_moments(camera, points, o, shared, out, [&](auto& px, auto& py, auto& pz, auto& b) {
      cubature_block(camera, c, px, py, pz, b);
    });
  }
  const SigmaPoses sigma = make_sigma_poses(pose, o.unscented);
  project_from_moments(camera, points, o, shared, out, [&](auto& px, auto& py, auto& pz, auto& b) {
    unscented_block(camera, sigma, px, py, pz, b);
  });
}

}  // namespace

void project_vertices(const Camera& camera, const UncertainPose& pose,
                      std::span<const Vec3> points, const ProjectionOptions& o,
                      std::vector<ProjectedVertex>& out) {
  out.clear();
  // An unbounded pose has no covariance to transform (it may hold infinities).
  const bool use_covariance = !pose.unbounded;
  ProjectionFlags shared;
  shared.unbounded = pose.unbounded;
  shared.rotation_too_uncertain =
      use_covariance && rotation_too_uncertain(pose.covariance, o.max_rotation_sigma_rad);
  if (use_covariance) {
    if (o.method == ProjectionMethod::unscented)
      project_unscented(camera, pose, points, o, shared, out);
    else
      project_linear(camera, pose, points, o, shared, out);
  } else {
    // LOST: the pixel of the last estimate, no covariance.
    const double fold_r2 = camera.distortion_fold_r2();
    for (const Vec3& p : points) {
      const Vec3 pc = pose.T * p;
      ProjectedVertex& v = start_vertex(out, pc.z(), shared, o);
      if (v.flags.behind_camera) continue;
      v.mean_px = camera.project(pc);
      v.flags.past_distortion_fold = pc.head<2>().squaredNorm() >= fold_r2 * pc.z() * pc.z();
    }
  }
  // A NaN compares false with every bound above (a NaN depth is not behind the camera),
  // so non-finite numbers, from the input or from an overflow, are caught in the results:
  // in one sum per vertex, which a NaN or an infinity (or numbers near the largest double,
  // whose sum overflows) makes non-finite.
  for (ProjectedVertex& v : out)
    v.flags.not_finite =
        !std::isfinite(v.depth_m + v.depth_sigma_m + v.mean_px.sum() + v.covariance_px2.sum());
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
