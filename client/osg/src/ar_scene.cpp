#include "covtrack/osg/ar_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <osg/BlendFunc>
#include <osg/Geode>
#include <osg/Image>
#include <osg/Light>
#include <osg/LightSource>
#include <osg/LineWidth>

#include "covtrack/osg/camera_matrices.hpp"
#include "covtrack/osg/lens_warp.hpp"

namespace covtrack::ar {
namespace {

// A camera drawing in the image's pixels, before or after the viewer's own.
osg::ref_ptr<osg::Camera> pixel_camera(const client::Camera& c, osg::Camera::RenderOrder order, int order_num = 0) {
  osg::ref_ptr<osg::Camera> cam = new osg::Camera;
  cam->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
  cam->setRenderOrder(order, order_num);
  cam->setViewport(0, 0, c.width_px, c.height_px);
  cam->setProjectionMatrix(pixel_projection(c));
  cam->setViewMatrix(osg::Matrixd::identity());
  cam->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
  osg::StateSet* state = cam->getOrCreateStateSet();
  state->setMode(GL_LIGHTING, osg::StateAttribute::OFF | osg::StateAttribute::OVERRIDE);
  state->setMode(GL_DEPTH_TEST, osg::StateAttribute::OFF | osg::StateAttribute::OVERRIDE);
  return cam;
}

// Text in the overlay's pixels, hidden until set.
osg::ref_ptr<osgText::Text> overlay_text(const osg::Vec4& colour) {
  osg::ref_ptr<osgText::Text> text = new osgText::Text;
  text->setDataVariance(osg::Object::DYNAMIC);
  text->setColor(colour);
  // The overlay's v grows downwards: the glyphs are turned over to stand upright.
  text->setAxisAlignment(osgText::TextBase::USER_DEFINED_ROTATION);
  text->setRotation(osg::Quat(M_PI, osg::X_AXIS));
  text->setAlignment(osgText::TextBase::LEFT_CENTER);
  text->setNodeMask(0);
  return text;
}

// `text` in `box`, its glyphs as high as 0.8 of the box and shrunk until it fits.
void put_text(osgText::Text& text, const std::string& content, const client::Box& box) {
  text.setText(content);
  text.setCharacterSize(float(0.8 * box.height()));
  if (const osg::BoundingBox bb = text.computeBoundingBox(); bb.valid() && bb.xMax() - bb.xMin() > box.width())
    text.setCharacterSize(float(0.8 * box.height() * box.width() / (bb.xMax() - bb.xMin())));
  text.setPosition(osg::Vec3(float(box.min.x()), float(box.center().y()), 0));
  text.setNodeMask(~0u);
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

// Drawables are nodes too (OSG 3.4 on): one call sets either's render bin.
void in_bin(osg::Node& node, int bin, const char* kind, osg::StateSet::RenderBinMode mode) {
  node.getOrCreateStateSet()->setRenderBinDetails(bin, kind, mode);
}

void finish_lines(osg::Geometry& g) {
  g.getVertexArray()->dirty();
  g.dirtyBound();
}

}  // namespace

ArScene::ArScene(client::Camera camera, ArSceneOptions options)
    : camera_(std::move(camera)), options_(options), root_(new osg::Group), objects_(new osg::Group) {
  build_background();
  if (camera_.has_distortion())
    build_lens();
  else
    root_->addChild(objects_);  // drawn by the viewer's camera
  build_overlay();
}

void ArScene::build_lens() {
  const LensCanvas canvas = lens_canvas(camera_);
  osg::ref_ptr<osg::Texture2D> texture = new osg::Texture2D;
  texture->setTextureSize(canvas.pinhole.width_px, canvas.pinhole.height_px);
  texture->setInternalFormat(GL_RGBA);
  texture->setFilter(osg::Texture::MIN_FILTER, osg::Texture::LINEAR);
  texture->setFilter(osg::Texture::MAG_FILTER, osg::Texture::LINEAR);
  texture->setResizeNonPowerOfTwoHint(false);
  // The objects through the canvas's pinhole, into the texture, on a clear background.
  lens_ = new osg::Camera;
  lens_->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
  lens_->setRenderOrder(osg::Camera::PRE_RENDER, 1);
  lens_->setRenderTargetImplementation(osg::Camera::FRAME_BUFFER_OBJECT);
  lens_->attach(osg::Camera::COLOR_BUFFER, texture.get());
  lens_->setViewport(0, 0, canvas.pinhole.width_px, canvas.pinhole.height_px);
  lens_->setClearColor(osg::Vec4(0, 0, 0, 0));
  lens_->setClearMask(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  lens_->setProjectionMatrix(projection_of(canvas.pinhole, options_.near_m, options_.far_m));
  lens_->setViewMatrix(opencv_to_eye());
  lens_->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
  // A camera drawing into a texture has no share of the viewer's headlight: its own, a
  // light from the eye as the viewer's is.
  osg::ref_ptr<osg::Light> light = new osg::Light(0);
  light->setPosition(osg::Vec4(0, 0, 1, 0));
  light->setAmbient(osg::Vec4(0.05f, 0.05f, 0.05f, 1));
  light->setDiffuse(osg::Vec4(0.8f, 0.8f, 0.8f, 1));
  light->setSpecular(osg::Vec4(1, 1, 1, 1));
  osg::ref_ptr<osg::LightSource> headlight = new osg::LightSource;
  headlight->setLight(light);
  headlight->setReferenceFrame(osg::LightSource::ABSOLUTE_RF);
  headlight->setLocalStateSetModes(osg::StateAttribute::ON);
  headlight->addChild(objects_);
  lens_->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::ON);
  lens_->addChild(headlight);
  root_->addChild(lens_);
  // Then laid over the video, bent as the lens bends it.
  osg::ref_ptr<osg::Camera> warp = pixel_camera(camera_, osg::Camera::POST_RENDER, 0);
  warp->setClearMask(0);
  osg::ref_ptr<osg::Geometry> mesh = lens_warp_mesh(camera_, canvas);
  osg::StateSet* state = mesh->getOrCreateStateSet();
  state->setTextureAttributeAndModes(0, texture, osg::StateAttribute::ON);
  state->setAttributeAndModes(new osg::BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA));
  osg::ref_ptr<osg::Geode> geode = new osg::Geode;
  geode->addDrawable(mesh);
  warp->addChild(geode);
  root_->addChild(warp);
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
  overlay_ = pixel_camera(camera_, osg::Camera::POST_RENDER, 1);
  overlay_->setClearMask(0);
  overlay_->getOrCreateStateSet()->setAttributeAndModes(new osg::LineWidth(options_.line_width_px));
  outer_lines_ = line_geometry(options_.outer_colour);
  inner_lines_ = line_geometry(options_.inner_colour);
  selected_lines_ = line_geometry(options_.selected_colour);
  preselected_lines_ = line_geometry(options_.preselected_colour);
  pointer_lines_ = line_geometry(options_.pointer_colour);
  target_panels_ = line_geometry(options_.target_panel_colour);
  target_lines_ = line_geometry(options_.pointer_colour);
  osg::ref_ptr<osg::Geode> lines = new osg::Geode;
  for (osg::Geometry* g : overlay_lines()) lines->addDrawable(g);
  labels_ = new osg::Geode;
  target_labels_ = new osg::Geode;
  // Drawing order by render bin: the lines (0), the objects' labels (1), the two-step
  // targets' panels (2) and outlines (3), their names (4). Text asks for the transparent
  // bin itself: the labels' bins override that.
  in_bin(*labels_, 1, "DepthSortedBin", osg::StateSet::OVERRIDE_RENDERBIN_DETAILS);
  in_bin(*target_panels_, 2, "RenderBin", osg::StateSet::USE_RENDERBIN_DETAILS);
  in_bin(*target_lines_, 3, "RenderBin", osg::StateSet::USE_RENDERBIN_DETAILS);
  in_bin(*target_labels_, 4, "DepthSortedBin", osg::StateSet::OVERRIDE_RENDERBIN_DETAILS);
  overlay_->addChild(lines);
  overlay_->addChild(labels_);
  overlay_->addChild(target_labels_);
  root_->addChild(overlay_);
}

void ArScene::add_object(std::vector<osg::ref_ptr<osg::Node>> per_level) {
  osg::ref_ptr<osg::MatrixTransform> transform = new osg::MatrixTransform;
  transform->setDataVariance(osg::Object::DYNAMIC);
  osg::ref_ptr<osg::Switch> levels = new osg::Switch;
  for (const auto& node : per_level) levels->addChild(node, false);
  if (levels->getNumChildren() > 0) levels->setSingleChildOn(0);
  transform->addChild(levels);
  objects_->addChild(transform);
  transforms_.push_back(transform);
  switches_.push_back(levels);
  texts_.push_back(overlay_text(options_.label_colour));
  labels_->addDrawable(texts_.back());
}

void ArScene::configure(osg::Camera& viewer_camera) const {
  viewer_camera.setViewport(0, 0, camera_.width_px, camera_.height_px);
  if (lens_) {  // the objects are drawn through the lens; this camera draws nothing itself
    viewer_camera.setClearMask(0);
    return;
  }
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

void ArScene::update(const client::ArFrame& frame, std::span<const std::string> label_texts,
                     const SelectionDrawing* selection) {
  for (osg::Geometry* g : overlay_lines()) clear_lines(*g);
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
    // The placer sized the box for the application's own text measure: the glyphs shrink
    // until this font's text fits it too.
    put_text(text, label_texts[i], o.label.box);
    if (o.label.leader && options_.draw_regions) {
      const client::Vec2 leader[2] = {(*o.label.leader)[0], (*o.label.leader)[1]};
      add_lines(*outer_lines_, GL_LINES, leader);
    }
  }
  for (std::size_t i = n; i < texts_.size(); ++i) texts_[i]->setNodeMask(0);
  for (auto& text : target_texts_) text->setNodeMask(0);
  if (selection) draw_selection(frame, *selection);
  for (osg::Geometry* g : overlay_lines()) finish_lines(*g);
}

std::array<osg::Geometry*, 7> ArScene::overlay_lines() const {
  // In drawing order: a selection's outlines over the regions, its targets over all.
  return {outer_lines_.get(),   inner_lines_.get(),   preselected_lines_.get(), selected_lines_.get(),
          pointer_lines_.get(), target_panels_.get(), target_lines_.get()};
}

void ArScene::draw_selection(const client::ArFrame& frame, const SelectionDrawing& selection) {
  const auto outline = [&](std::optional<int> object, osg::Geometry& lines) {
    if (object && *object >= 0 && static_cast<std::size_t>(*object) < frame.objects.size())
      add_lines(lines, GL_LINE_LOOP, frame.objects[static_cast<std::size_t>(*object)].regions.outer);
  };
  if (selection.preselected != selection.selected) outline(selection.preselected, *preselected_lines_);
  outline(selection.selected, *selected_lines_);
  add_lines(*pointer_lines_, GL_LINE_LOOP, selection.pointer_region);
  for (std::size_t k = 0; k < selection.targets.size(); ++k) {
    const client::Box& box = selection.targets[k].box;
    const client::Polygon corners = client::box_polygon(box);
    add_lines(*target_panels_, GL_TRIANGLE_FAN, corners);
    add_lines(*target_lines_, GL_LINE_LOOP, corners);
    if (k >= target_texts_.size()) {
      target_texts_.push_back(overlay_text(options_.pointer_colour));
      target_labels_->addDrawable(target_texts_.back());
    }
    if (k < selection.target_names.size()) put_text(*target_texts_[k], selection.target_names[k], box);
  }
}

}  // namespace covtrack::ar
