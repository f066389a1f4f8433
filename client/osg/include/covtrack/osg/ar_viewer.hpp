#pragma once
// A viewer that draws an ArScene in a window, or off screen (a pbuffer, for files and
// tests), and hands back each frame as an OpenCV image. Both need an X display with
// OpenGL; headless machines run it under `xvfb-run` (Mesa draws in software).
#include <memory>
#include <string>

#include <opencv2/core.hpp>
#include <osg/Image>
#include <osgViewer/Viewer>

#include "covtrack/osg/ar_scene.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::ar {

class ArViewer {
 public:
  enum class Output { window, offscreen };

  // Fails, saying how to get one, when there is no display or no OpenGL context.
  static Result<std::unique_ptr<ArViewer>> open(ArScene& scene, Output output, const std::string& title = "covtrack ar");

  // Draws one frame; false once the window is closed (or Esc pressed in it).
  bool frame();
  // The frame last drawn: 8-bit BGR, top row first, the camera's size.
  cv::Mat image() const;

 private:
  ArViewer() = default;

  osgViewer::Viewer viewer_;
  osg::ref_ptr<osg::Image> pixels_;
};

}  // namespace covtrack::ar
