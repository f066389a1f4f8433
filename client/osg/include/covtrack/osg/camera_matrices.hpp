#pragma once
// The matrices that make OpenSceneGraph draw what a calibrated camera sees: covtrack's
// poses and cameras use OpenCV's camera frame (x right, y down, z forward; pixel centres
// at integer coordinates), OpenGL's eye frame looks down -z with y up and puts pixel
// centres at half-integers. Lens distortion is not drawn: OpenGL projects through the
// pinhole part only, so a renderer over video should undistort the video (or use a camera
// calibrated without distortion) for the drawing to line up with the regions.
#include <osg/Matrixd>

#include "covtrack/client/camera.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::ar {

// The pose as an OSG matrix (OSG multiplies row vectors: p' = p * M).
osg::Matrixd osg_matrix(const Pose& T);

// OpenCV's camera frame to OpenGL's eye frame: the view matrix of a scene whose root is
// the camera frame.
osg::Matrixd opencv_to_eye();

// The projection of the camera's pinhole part onto its image of width_px x height_px,
// with depths between near_m and far_m kept (0 < near_m < far_m).
osg::Matrixd projection_of(const client::Camera& camera, double near_m, double far_m);

// An orthographic projection in OpenCV pixels over the camera's image: (u, v) from the
// top-left pixel's centre, v down. For overlays drawn in pixels (regions, labels, video).
osg::Matrixd pixel_projection(const client::Camera& camera);

}  // namespace covtrack::ar
