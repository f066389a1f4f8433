#include "covtrack/osg/camera_matrices.hpp"

#include <Eigen/Core>

namespace covtrack::ar {
namespace {
// OSG stores a matrix in OpenGL's memory order, which is Eigen's column-major order of
// the same matrix written for column vectors.
osg::Matrixd from_column_vector_matrix(const Eigen::Matrix4d& m) { return osg::Matrixd(m.data()); }
}  // namespace

osg::Matrixd osg_matrix(const Pose& T) { return from_column_vector_matrix(T.matrix()); }

osg::Matrixd opencv_to_eye() { return from_column_vector_matrix(Eigen::Vector4d(1, -1, -1, 1).asDiagonal()); }

osg::Matrixd projection_of(const client::Camera& c, double near_m, double far_m) {
  // Clip coordinates for an eye point (x, y, z), z < 0 in front: w = -z, and the window
  // position of pixel (u, v) = (fx x/-z + cx, fy -y/-z + cy) is (u + 1/2, H - v - 1/2).
  const double W = c.width_px, H = c.height_px;
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 2 * c.fx / W;
  P(0, 2) = 1 - 2 * (c.cx + 0.5) / W;
  P(1, 1) = 2 * c.fy / H;
  P(1, 2) = 2 * (c.cy + 0.5) / H - 1;
  P(2, 2) = -(far_m + near_m) / (far_m - near_m);
  P(2, 3) = -2 * far_m * near_m / (far_m - near_m);
  P(3, 2) = -1;
  return from_column_vector_matrix(P);
}

osg::Matrixd pixel_projection(const client::Camera& c) {
  return osg::Matrixd::ortho2D(-0.5, c.width_px - 0.5, c.height_px - 0.5, -0.5);
}

}  // namespace covtrack::ar
