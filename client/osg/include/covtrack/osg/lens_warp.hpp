#pragma once
// Drawing through a lens with distortion. OpenGL projects through a pinhole only, so the
// 3-D scene is drawn first into a texture (a pinhole "canvas" wide enough to cover the
// whole image once undistorted), and the texture is then laid on a mesh whose vertices
// sit where the lens model puts each canvas point: a grid over the undistorted normalised
// plane, each vertex at client::Camera::pixel_of_normalised of its point. The drawing then
// has the same distortion as the regions, which follow the full lens model. Cells beyond
// the lens model's fold (where it maps back into the image) are left out.
#include <osg/Geometry>

#include "covtrack/client/camera.hpp"

namespace covtrack::ar {

struct LensCanvas {
  client::Camera pinhole;  // the canvas: the camera's focal lengths, no distortion
  // The undistorted normalised coordinates it covers.
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;
};

// The canvas covering every pixel of the camera's image once undistorted (cv::undistortPoints
// on the border), within the fold, at the image's pixel density; at most 4096 px a side.
LensCanvas lens_canvas(const client::Camera& camera);

// The mesh in the camera's pixels (v down), its texture coordinates into the canvas
// texture as OpenGL drew it (rows from the bottom). `cells` along the longer side.
osg::ref_ptr<osg::Geometry> lens_warp_mesh(const client::Camera& camera, const LensCanvas& canvas, int cells = 64);

}  // namespace covtrack::ar
