#include "covtrack/osg/lens_warp.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "covtrack/protocol/camera_opencv.hpp"

namespace covtrack::ar {

LensCanvas lens_canvas(const client::Camera& c) {
  // The image's border, every 8 px, undistorted to normalised coordinates.
  std::vector<cv::Point2d> border;
  const double right = c.width_px - 0.5, bottom = c.height_px - 0.5;
  for (double u = -0.5; u < right; u += 8) border.insert(border.end(), {{u, -0.5}, {u, bottom}});
  for (double v = -0.5; v < bottom; v += 8) border.insert(border.end(), {{-0.5, v}, {right, v}});
  border.insert(border.end(), {{right, -0.5}, {right, bottom}});
  std::vector<cv::Point2d> normalised;
  cv::undistortPoints(border, normalised, camera_matrix(c), distortion_vector(c));
  LensCanvas out;
  out.x_min = out.y_min = std::numeric_limits<double>::infinity();
  out.x_max = out.y_max = -std::numeric_limits<double>::infinity();
  // Past the fold the model has no inverse: the canvas stops at the fold's radius.
  const double fold_r = std::sqrt(c.distortion_fold_r2());
  for (cv::Point2d p : normalised) {
    if (const double r = std::hypot(p.x, p.y); r > fold_r) p *= fold_r / r;
    out.x_min = std::min(out.x_min, p.x), out.x_max = std::max(out.x_max, p.x);
    out.y_min = std::min(out.y_min, p.y), out.y_max = std::max(out.y_max, p.y);
  }
  // One pixel of margin, at the image's density, capped for the texture.
  constexpr int kMaxSide = 4096;
  out.x_min -= 1 / c.fx, out.x_max += 1 / c.fx, out.y_min -= 1 / c.fy, out.y_max += 1 / c.fy;
  out.pinhole.width_px = std::min(kMaxSide, static_cast<int>(std::ceil(c.fx * (out.x_max - out.x_min))));
  out.pinhole.height_px = std::min(kMaxSide, static_cast<int>(std::ceil(c.fy * (out.y_max - out.y_min))));
  out.pinhole.fx = out.pinhole.width_px / (out.x_max - out.x_min);
  out.pinhole.fy = out.pinhole.height_px / (out.y_max - out.y_min);
  // Pixel centres at integers: x_min is the canvas's left edge, u = -0.5.
  out.pinhole.cx = -0.5 - out.pinhole.fx * out.x_min;
  out.pinhole.cy = -0.5 - out.pinhole.fy * out.y_min;
  return out;
}

osg::ref_ptr<osg::Geometry> lens_warp_mesh(const client::Camera& c, const LensCanvas& canvas, int cells) {
  const double width = canvas.x_max - canvas.x_min, height = canvas.y_max - canvas.y_min;
  const int nx = width >= height ? cells : std::max(1, static_cast<int>(std::lround(cells * width / height)));
  const int ny = width >= height ? std::max(1, static_cast<int>(std::lround(cells * height / width))) : cells;
  const double fold_r2 = c.distortion_fold_r2();
  osg::ref_ptr<osg::Vec3Array> vertices = new osg::Vec3Array;
  osg::ref_ptr<osg::Vec2Array> texture = new osg::Vec2Array;
  const auto corner = [&](int i, int j) {
    const double x = canvas.x_min + width * i / nx, y = canvas.y_min + height * j / ny;
    double u = 0, v = 0;
    c.pixel_of_normalised(x, y, u, v);
    vertices->push_back(osg::Vec3(float(u), float(v), 0));
    // The canvas as OpenGL drew it: u' = fx' x + cx' at s = (u' + 1/2) / W', rows from the bottom.
    const client::Camera& p = canvas.pinhole;
    texture->push_back(osg::Vec2(float((p.fx * x + p.cx + 0.5) / p.width_px),
                                 float(1 - (p.fy * y + p.cy + 0.5) / p.height_px)));
  };
  const auto inside_fold = [&](int i, int j) {
    const double x = canvas.x_min + width * i / nx, y = canvas.y_min + height * j / ny;
    return x * x + y * y < fold_r2;
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (!inside_fold(i, j) || !inside_fold(i + 1, j) || !inside_fold(i, j + 1) || !inside_fold(i + 1, j + 1)) continue;
      for (const auto& [di, dj] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}}) corner(i + di, j + dj);
    }
  osg::ref_ptr<osg::Geometry> mesh = new osg::Geometry;
  mesh->setVertexArray(vertices);
  mesh->setTexCoordArray(0, texture);
  osg::ref_ptr<osg::Vec4Array> white = new osg::Vec4Array;
  white->push_back(osg::Vec4(1, 1, 1, 1));
  mesh->setColorArray(white, osg::Array::BIND_OVERALL);
  mesh->addPrimitiveSet(new osg::DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices->size())));
  return mesh;
}

}  // namespace covtrack::ar
