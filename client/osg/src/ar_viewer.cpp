#include "covtrack/osg/ar_viewer.hpp"

#include <cstdlib>

#include <opencv2/imgproc.hpp>

namespace covtrack::ar {
namespace {

// Reads the frame back once the viewer's camera has drawn it.
struct ReadPixels : osg::Camera::DrawCallback {
  ReadPixels(osg::Image* image, int width, int height) : image(image), width(width), height(height) {}
  void operator()(osg::RenderInfo&) const override { image->readPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE); }
  osg::Image* image;
  int width, height;
};

}  // namespace

Result<std::unique_ptr<ArViewer>> ArViewer::open(ArScene& scene, Output output, const std::string& title) {
  if (!std::getenv("DISPLAY"))
    return fail("no display (DISPLAY is not set): OpenGL needs an X server; on a machine without one, run under "
                "xvfb-run -a");
  const client::Camera& camera = scene.camera();
  osg::ref_ptr<osg::GraphicsContext::Traits> traits = new osg::GraphicsContext::Traits;
  traits->readDISPLAY();
  if (traits->displayNum < 0) traits->displayNum = 0;
  traits->width = camera.width_px, traits->height = camera.height_px;
  traits->windowName = title;
  traits->windowDecoration = output == Output::window;
  traits->pbuffer = output == Output::offscreen;
  traits->doubleBuffer = output == Output::window;
  osg::ref_ptr<osg::GraphicsContext> context = osg::GraphicsContext::createGraphicsContext(traits.get());
  if (!context)
    return fail("no OpenGL context on display " + traits->displayName() +
                (output == Output::offscreen ? " (an off-screen pbuffer)" : " (a window)"));
  std::unique_ptr<ArViewer> v(new ArViewer);
  v->viewer_.setThreadingModel(osgViewer::Viewer::SingleThreaded);  // ArScene::update runs between frames
  osg::Camera* view_camera = v->viewer_.getCamera();
  view_camera->setGraphicsContext(context);
  scene.configure(*view_camera);
  view_camera->setDrawBuffer(traits->doubleBuffer ? GL_BACK : GL_FRONT);
  view_camera->setReadBuffer(traits->doubleBuffer ? GL_BACK : GL_FRONT);
  v->pixels_ = new osg::Image;
  view_camera->setFinalDrawCallback(new ReadPixels(v->pixels_.get(), camera.width_px, camera.height_px));
  v->viewer_.setSceneData(scene.root());
  v->viewer_.setKeyEventSetsDone(osgGA::GUIEventAdapter::KEY_Escape);
  v->viewer_.realize();
  if (!v->viewer_.isRealized()) return fail("the OpenGL viewer could not start on display " + traits->displayName());
  return v;
}

bool ArViewer::frame() {
  if (viewer_.done()) return false;
  viewer_.frame();
  return !viewer_.done();
}

cv::Mat ArViewer::image() const {
  if (!pixels_->data()) return {};
  const cv::Mat rgb(pixels_->t(), pixels_->s(), CV_8UC3, pixels_->data());
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::flip(bgr, bgr, 0);  // OpenGL's rows start at the bottom
  return bgr;
}

}  // namespace covtrack::ar
