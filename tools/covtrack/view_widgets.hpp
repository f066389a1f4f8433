#pragma once
// The adaptive widgets (docs/background.md) for each frame of `covtrack view`: every
// object's Level-of-Error choice (5.6.2; its hysteresis needs the frames before, so this
// object lives as long as the view) and, when the scene has a pointer, each object's
// selection likelihood and the selection it makes (chapter 6). In a session with a user
// (a window, or scripted clicks: selection_input.hpp) the pointer may also be the mouse,
// and clicks select.
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/client/level_of_error.hpp"
#include "covtrack/client/selection.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/scene/scene.hpp"
#include "regions_report.hpp"
#include "selection_state.hpp"

namespace covtrack::cli {

struct WidgetFrame {
  std::vector<scene::Augmentation> augmentations;  // the chosen one, per object
  // With a pointer: per object, in [0, 1]; the selection; and, when several objects are
  // candidates, the indirect targets (6.6.2) laid out above the pointer.
  std::optional<client::Pointer> pointer;
  std::vector<double> likelihoods;
  client::DirectSelection selection;  // what the pointer selects now (preselection)
  bool preselect = true;              // false: a user turned preselection off
  std::vector<client::SelectionTarget> targets;
  // With a user: the object clicked, and the technique ("direct" or "two-step").
  std::optional<int> clicked;
  std::string technique;
};

class ViewWidgets {
 public:
  // Fails naming the object whose Level-of-Error thresholds are invalid.
  static Result<ViewWidgets> create(const scene::Scene& scene);

  // `user`: this frame of a session with a user; its pointer and clicks replace the
  // scene's pointer alone, and the targets shown are those its clicks laid out.
  WidgetFrame update(const RegionsReport& report, const cv::Size& screen, const SelectionState* user = nullptr);

 private:
  ViewWidgets(std::vector<client::LevelOfError> levels, const scene::Scene& scene);

  std::vector<client::LevelOfError> levels_;  // one per object
  std::vector<std::vector<scene::Augmentation>> augmentations_;
  std::optional<scene::Likelihood> likelihood_;  // none: the scene has no pointer
};

}  // namespace covtrack::cli
