#include "covtrack/osg/ar_scene.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <osg/Depth>
#include <osg/Geode>
#include <osg/Image>
#include <osg/LineWidth>

#include "covtrack/osg/camera_matrices.hpp"

namespace covtrack::ar {
namespace {

// A camera drawing in the image's pixels, before or after the viewer's own.
osg::ref_ptr<osg::Camera> pixel_camera(const client::Camera& c, osg::Camera::RenderOrder order) {
  osg::ref_ptr<osg::Camera> cam = new osg::Camera;
  cam->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
  cam->setRenderOrder(order);
  cam->setViewport(0, 0, c.width_px, c.height_px);
  cam->setProjectionMatrix(pixel_projection(c));
  cam->setViewMatrix(osg::Matrixd::identity());
  cam->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
  osg::StateSet* state = cam->getOrCreateStateSet();
  state->setMode(GL_LIGHTING, osg::StateAttribute::OFF | osg::StateAttribute::OVERRIDE);
  state->setMode(GL_DEPTH_TEST, osg::StateAttribute::OFF | osg::StateAttribute::OVERRIDE);
  return cam;
}

// Line loops rebuilt every frame, in one colour.
osg::ref_ptr<osg::Geometry> line_geometry(const osg::Vec4& colour) {
  osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
  g->setDataVariance(osg::Object::DYNAMIC);
  g->setUseDisplayList(false);
  g->setUseVertexBufferObjects(true);
  g->setVertexArray(new osg::Vec3Array);
  osg::ref_ptr<osg::Vec4Array> colours = new osg::Vec4Array;
  colours->push_back(colour);
  g->setColorArray(colours, osg::Array::BIND_OVERALL);
  return g;
}

void clear_lines(osg::Geometry& g) {
  static_cast<osg::Vec3Array*>(g.getVertexArray())->clear();
  g.removePrimitiveSet(0, g.getNumPrimitiveSets());
}

void add_lines(osg::Geometry& g, GLenum mode, std::span<const client::Vec2> points) {
  if (points.size() < 2) return;
  auto* v = static_cast<osg::Vec3Array*>(g.getVertexArray());
  const auto first = static_cast<GLint>(v->size());
  for (const client::Vec2& p : points) v->push_back(osg::Vec3(float(p.x()), float(p.y()), 0));
  g.addPrimitiveSet(new osg::DrawArrays(mode, first, static_cast<GLsizei>(points.size())));
}

void finish_lines(osg::Geometry& g) {
  g.getVertexArray()->dirty();
  g.dirtyBound();
}

}  // namespace

ArScene::ArScene(client::Camera camera, ArSceneOptions options)
    : camera_(std::move(camera)), options_(options), root_(new osg::Group) {
  build_background();
  build_overlay();
}

void ArScene::build_background() {
  background_ = pixel_camera(camera_, osg::Camera::PRE_RENDER);
  background_->setClearMask(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  background_->setClearColor(options_.clear_colour);
  const float W = float(camera_.width_px), H = float(camera_.height_px);
  video_quad_ = new osg::Geometry;
  osg::ref_ptr<osg::Vec3Array> corners = new osg::Vec3Array;
  osg::ref_ptr<osg::Vec2Array> texture = new osg::Vec2Array;
  // The image's first row is the top one, at the texture's t = 0.
  for (const auto& [u, v] : {std::pair{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}}) {
    corners->push_back(osg::Vec3(u * W - 0.5f, v * H - 0.5f, 0));
    texture->push_back(osg::Vec2(u, v));
  }
  video_quad_->setVertexArray(corners);
  video_quad_->setTexCoordArray(0, texture);
  osg::ref_ptr<osg::Vec4Array> white = new osg::Vec4Array;
  white->push_back(osg::Vec4(1, 1, 1, 1));
  video_quad_->setColorArray(white, osg::Array::BIND_OVERALL);
  video_quad_->addPrimitiveSet(new osg::DrawArrays(GL_QUADS, 0, 4));
  video_ = new osg::Texture2D;
  video_->setResizeNonPowerOfTwoHint(false);
  video_->setFilter(osg::Texture::MIN_FILTER, osg::Texture::LINEAR);
  video_->setFilter(osg::Texture::MAG_FILTER, osg::Texture::LINEAR);
  video_->setDataVariance(osg::Object::DYNAMIC);
  video_quad_->getOrCreateStateSet()->setTextureAttributeAndModes(0, video_, osg::StateAttribute::ON);
  video_quad_->setNodeMask(0);  // until a frame is set
  osg::ref_ptr<osg::Geode> geode = new osg::Geode;
  geode->addDrawable(video_quad_);
  background_->addChild(geode);
  root_->addChild(background_);
}

void ArScene::build_overlay() {
  overlay_ = pixel_camera(camera_, osg::Camera::POST_RENDER);
  overlay_->setClearMask(0);
  overlay_->getOrCreateStateSet()->setAttributeAndModes(new osg::LineWidth(options_.line_width_px));
  outer_lines_ = line_geometry(options_.outer_colour);
  inner_lines_ = line_geometry(options_.inner_colour);
  osg::ref_ptr<osg::Geode> lines = new osg::Geode;
  lines->addDrawable(outer_lines_);
  lines->addDrawable(inner_lines_);
  labels_ = new osg::Geode;
  overlay_->addChild(lines);
  overlay_->addChild(labels_);
  root_->addChild(overlay_);
}

void ArScene::add_object(std::vector<osg::ref_ptr<osg::Node>> per_level) {
  osg::ref_ptr<osg::MatrixTransform> transform = new osg::MatrixTransform;
  transform->setDataVariance(osg::Object::DYNAMIC);
  osg::ref_ptr<osg::Switch> levels = new osg::Switch;
  for (const auto& node : per_level) levels->addChild(node, false);
  if (levels->getNumChildren() > 0) levels->setSingleChildOn(0);
  transform->addChild(levels);
  root_->addChild(transform);
  transforms_.push_back(transform);
  switches_.push_back(levels);
  osg::ref_ptr<osgText::Text> text = new osgText::Text;
  text->setDataVariance(osg::Object::DYNAMIC);
  text->setColor(options_.label_colour);
  // The overlay's v grows downwards: the glyphs are turned over to stand upright.
  text->setAxisAlignment(osgText::TextBase::USER_DEFINED_ROTATION);
  text->setRotation(osg::Quat(M_PI, osg::X_AXIS));
  text->setAlignment(osgText::TextBase::LEFT_CENTER);
  text->setNodeMask(0);
  labels_->addDrawable(text);
  texts_.push_back(text);
}

void ArScene::configure(osg::Camera& viewer_camera) const {
  viewer_camera.setViewport(0, 0, camera_.width_px, camera_.height_px);
  viewer_camera.setProjectionMatrix(projection_of(camera_, options_.near_m, options_.far_m));
  viewer_camera.setViewMatrix(opencv_to_eye());
  // OSG would otherwise move the near and far planes to the scene's bounds each frame.
  viewer_camera.setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
  viewer_camera.setClearMask(GL_DEPTH_BUFFER_BIT);
}

void ArScene::set_video(const cv::Mat& frame) {
  if (frame.empty()) {
    video_quad_->setNodeMask(0);
    return;
  }
  cv::Mat rgb;
  if (frame.channels() == 1)
    cv::cvtColor(frame, rgb, cv::COLOR_GRAY2RGB);
  else
    cv::cvtColor(frame, rgb, cv::COLOR_BGR2RGB);
  osg::ref_ptr<osg::Image> image = new osg::Image;
  const auto bytes = rgb.total() * rgb.elemSize();
  auto* data = new unsigned char[bytes];
  std::copy(rgb.data, rgb.data + bytes, data);  // cvtColor's output is continuous
  image->setImage(rgb.cols, rgb.rows, 1, GL_RGB, GL_RGB, GL_UNSIGNED_BYTE, data, osg::Image::USE_NEW_DELETE, 1);
  video_->setImage(image);
  video_quad_->setNodeMask(~0u);
}

void ArScene::update(const client::ArFrame& frame, std::span<const std::string> label_texts) {
  clear_lines(*outer_lines_);
  clear_lines(*inner_lines_);
  const std::size_t n = std::min(frame.objects.size(), transforms_.size());
  for (std::size_t i = 0; i < n; ++i) {
    const client::ArObjectFrame& o = frame.objects[i];
    transforms_[i]->setMatrix(osg_matrix(o.T_camera_object.T));
    if (const unsigned children = switches_[i]->getNumChildren(); children > 0)
      switches_[i]->setSingleChildOn(std::min(static_cast<unsigned>(std::max(o.level, 0)), children - 1));
    if (options_.draw_regions && o.regions.valid) {
      add_lines(*outer_lines_, GL_LINE_LOOP, o.regions.outer);
      add_lines(*inner_lines_, GL_LINE_LOOP, o.regions.inner);
    }
    osgText::Text& text = *texts_[i];
    const bool labelled = options_.draw_labels && i < label_texts.size() && !label_texts[i].empty();
    text.setNodeMask(labelled ? ~0u : 0);
    if (!labelled) continue;
    const client::Box& box = o.label.box;
    text.setText(label_texts[i]);
    // The placer sized the box for the application's own text measure: shrink the glyphs
    // until this font's text fits it too.
    text.setCharacterSize(float(0.8 * box.height()));
    if (const osg::BoundingBox bb = text.computeBoundingBox(); bb.valid() && bb.xMax() - bb.xMin() > box.width())
      text.setCharacterSize(float(0.8 * box.height() * box.width() / (bb.xMax() - bb.xMin())));
    text.setPosition(osg::Vec3(float(box.min.x()), float(box.center().y()), 0));
    if (o.label.leader && options_.draw_regions) {
      const client::Vec2 leader[2] = {(*o.label.leader)[0], (*o.label.leader)[1]};
      add_lines(*outer_lines_, GL_LINES, leader);
    }
  }
  for (std::size_t i = n; i < texts_.size(); ++i) texts_[i]->setNodeMask(0);
  finish_lines(*outer_lines_);
  finish_lines(*inner_lines_);
}

}  // namespace covtrack::ar
