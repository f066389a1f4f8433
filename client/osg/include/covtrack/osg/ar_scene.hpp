#pragma once
// An OpenSceneGraph scene for one calibrated camera, fed by client::ArView: each frame's
// poses, Level-of-Error levels, screen regions and labels copied into nodes.
//
//   root
//    |- background: a pre-render camera drawing the video frame (set_video) in pixels
//    |- objects: per object a transform (T_camera_object) over a Level-of-Error switch
//    |  whose children (any subgraphs, one per level) the application gives; through a
//    |  camera with lens distortion drawn into a texture and bent as the lens bends
//    |  (lens_warp.hpp)
//    '- overlay: a post-render camera drawing outer and inner regions, leader lines and
//       labels in pixels
//
// Without distortion the viewer's own camera draws the objects: configure() sets it to the
// calibration's projection and the OpenCV camera frame (camera_matrices.hpp), and leaves
// the colour buffer to the background.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <osg/Camera>
#include <osg/Geometry>
#include <osg/MatrixTransform>
#include <osg/Switch>
#include <osg/Texture2D>
#include <osgText/Text>

#include "covtrack/client/ar_view.hpp"
#include "covtrack/client/camera.hpp"
#include "covtrack/client/selection.hpp"

namespace covtrack::ar {

// What selection shows this frame (client::SelectionSession gives it): the selected and
// the preselected object's outer region, the pointer's region, and the targets of a
// two-step selection with their names.
struct SelectionDrawing {
  std::optional<int> selected, preselected;
  client::Polygon pointer_region;
  std::vector<client::SelectionTarget> targets;
  std::vector<std::string> target_names;  // one per target
};

struct ArSceneOptions {
  double near_m = 0.01, far_m = 100;       // depths the 3-D drawing keeps
  osg::Vec4 outer_colour{1, 0.8f, 0, 1};   // RGBA
  osg::Vec4 inner_colour{0, 0.9f, 1, 1};
  osg::Vec4 label_colour{1, 1, 1, 1};
  osg::Vec4 selected_colour{0.2f, 1, 0.3f, 1};
  osg::Vec4 preselected_colour{1, 1, 1, 1};
  osg::Vec4 pointer_colour{1, 0.3f, 1, 1};
  osg::Vec4 target_panel_colour{0.12f, 0.12f, 0.12f, 1};  // behind a two-step target's name
  osg::Vec4 clear_colour{0, 0, 0, 1};      // behind everything until a video frame is set
  float line_width_px = 2;
  bool draw_regions = true;
  bool draw_labels = true;
};

class ArScene {
 public:
  explicit ArScene(client::Camera camera, ArSceneOptions options = {});

  // The augmentation of the next object (ArFrame::objects in the same order): one
  // subgraph per Level-of-Error level; a level beyond the last shows the last.
  void add_object(std::vector<osg::ref_ptr<osg::Node>> per_level);

  // Sets the viewer's camera: the image's viewport, the calibration's projection, the
  // OpenCV camera frame as its view, and no colour clear (the background draws first).
  void configure(osg::Camera& viewer_camera) const;

  // The video frame behind the scene (8-bit grey or BGR; stretched to the image). An
  // empty image shows the clear colour.
  void set_video(const cv::Mat& frame);

  // Copies one frame of ArView into the scene. `label_texts`: one per object (empty: no
  // label text). Objects beyond those added are ignored. `selection`, if given, is drawn
  // over the regions.
  void update(const client::ArFrame& frame, std::span<const std::string> label_texts = {},
              const SelectionDrawing* selection = nullptr);

  osg::Group* root() const { return root_.get(); }
  const client::Camera& camera() const { return camera_; }

 private:
  void build_background();
  void build_lens();
  void build_overlay();

  client::Camera camera_;
  ArSceneOptions options_;
  osg::ref_ptr<osg::Group> root_, objects_;
  osg::ref_ptr<osg::Camera> background_, lens_, overlay_;
  osg::ref_ptr<osg::Texture2D> video_;
  osg::ref_ptr<osg::Geometry> video_quad_;
  void draw_selection(const client::ArFrame& frame, const SelectionDrawing& selection);
  std::array<osg::Geometry*, 7> overlay_lines() const;

  osg::ref_ptr<osg::Geometry> outer_lines_, inner_lines_, selected_lines_, preselected_lines_, pointer_lines_;
  // Two-step targets over everything else: a filled panel, its outline, its name.
  osg::ref_ptr<osg::Geometry> target_panels_, target_lines_;
  osg::ref_ptr<osg::Geode> labels_, target_labels_;
  std::vector<osg::ref_ptr<osgText::Text>> target_texts_;  // grown as targets need
  std::vector<osg::ref_ptr<osg::MatrixTransform>> transforms_;
  std::vector<osg::ref_ptr<osg::Switch>> switches_;
  std::vector<osg::ref_ptr<osgText::Text>> texts_;
};

}  // namespace covtrack::ar
