#include "scene_ar_view.hpp"

#include "view_labels.hpp"

namespace covtrack::cli {

Result<client::ArView> scene_ar_view(const RegionsModel& model, const cv::Size& screen,
                                     client::ProjectionMethod method) {
  std::vector<client::ArObject> objects;
  for (std::size_t i = 0; i < model.objects.size(); ++i) {
    const scene::SceneObject& o = model.scene.objects[i];
    // A "label" level does not rely on registration: its label goes to the list.
    std::vector<bool> listed;
    for (scene::Augmentation a : o.augmentations) listed.push_back(a == scene::Augmentation::label);
    objects.push_back({o.name, o.frame, model.objects[i].hull_vertices_m, o.level_of_error_px,
                       o.level_of_error_margin_px, listed});
  }
  client::ArViewOptions options;
  options.regions.projection.method = method;
  options.regions.regions.confidence = model.confidence;
  options.regions.assessment = {client::largest_semi_axis_px(model.confidence), client::max_value()};
  options.labels.screen = {client::Vec2(0, 0), client::Vec2(screen.width, screen.height)};
  options.label_box = [names = objects](std::size_t i, const client::ArObjectFrame& f) {
    return label_box_px(label_text(names[i].name, f.regions));
  };
  return client::ArView::create(model.camera, model.scene.camera.frame, std::move(objects), options);
}

}  // namespace covtrack::cli
