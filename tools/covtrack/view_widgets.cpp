#include "view_widgets.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "view_labels.hpp"

namespace covtrack::cli {

Result<ViewWidgets> ViewWidgets::create(const scene::Scene& scene) {
  std::vector<client::LevelOfError> levels;
  for (const scene::SceneObject& o : scene.objects) {
    auto loe = client::LevelOfError::create(o.level_of_error_px, o.level_of_error_margin_px);
    if (!loe) return fail(fmt::format("object {}: {}", o.name, loe.error().message));
    levels.push_back(*loe);
  }
  return ViewWidgets(std::move(levels), scene);
}

ViewWidgets::ViewWidgets(std::vector<client::LevelOfError> levels, const scene::Scene& scene)
    : levels_(std::move(levels)) {
  for (const scene::SceneObject& o : scene.objects) augmentations_.push_back(o.augmentations);
  if (scene.pointer) likelihood_ = scene.pointer->likelihood;
}

WidgetFrame ViewWidgets::update(const RegionsReport& report, const cv::Size& screen, const SelectionState* user) {
  WidgetFrame frame;
  for (std::size_t i = 0; i < report.objects.size(); ++i) {
    const int level = levels_[i].update(report.objects[i].regions.assessment);
    frame.augmentations.push_back(augmentations_[i][static_cast<std::size_t>(level)]);
  }
  if (user) {
    frame.clicked = user->selected;
    frame.technique = user->technique_name;
    frame.pointer = user->pointer;
    frame.preselect = user->preselect;
  } else if (likelihood_ && report.pointer_tip) {
    frame.pointer = client::pointer_from_projection(*report.pointer_tip, report.confidence);
  }
  if (!frame.pointer) return frame;

  const std::vector<client::Selectable> selectables = selectables_of(report);
  // A user's session has the area likelihoods already (for this pointer and these objects).
  if (likelihood_ == scene::Likelihood::distance)
    frame.likelihoods = client::likelihoods_by_distance(*frame.pointer, selectables);
  else
    frame.likelihoods = user ? user->likelihoods : client::likelihoods_by_area(*frame.pointer, selectables);
  if (frame.preselect) frame.selection = client::select_direct(frame.likelihoods, selectables);
  if (user) {
    frame.targets = user->targets;  // laid out by a click, waiting for the next
  } else if (frame.selection.ambiguous()) {
    client::IndirectOptions options;
    options.screen = {client::Vec2(0, 0), client::Vec2(screen.width, screen.height)};
    // Wide enough for the longest candidate's name: a cut name cannot be told apart.
    for (int object : frame.selection.candidates)
      options.target_size_px.x() = std::max(options.target_size_px.x(),
                                            label_box_px(report.objects[static_cast<std::size_t>(object)].name).x());
    frame.targets = client::layout_indirect_targets(frame.selection.candidates, *frame.pointer, options);
  }
  return frame;
}

}  // namespace covtrack::cli
