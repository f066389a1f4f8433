#pragma once
// Selection as a user performs it, frame after frame (dissertation chapter 6,
// docs/background.md): a pointer (the mouse, or a tracked stylus projected with its error)
// moves over the objects; a click selects. Two techniques, switchable at any time:
//  - direct: the click selects the most likely object under the pointer;
//  - two-step: a click on one candidate selects it, on several lays out one target per
//    candidate (spread by the pointer's error) and the next click picks a target.
// With preselection on, the most likely object under the pointer is named every frame
// before any click, so the user sees what a click would pick.
#include <optional>
#include <span>
#include <vector>

#include "covtrack/client/selection.hpp"

namespace covtrack::client {

enum class SelectionTechnique { direct, two_step };

class SelectionSession {
 public:
  explicit SelectionSession(TwoStepSelection::Options options = {},
                            SelectionTechnique technique = SelectionTechnique::two_step);

  // Switching drops targets laid out by the other technique.
  void set_technique(SelectionTechnique technique);
  SelectionTechnique technique() const { return technique_; }
  void set_preselect(bool on) { preselect_ = on; }
  bool preselect() const { return preselect_; }

  // Each frame: where the pointer is, and the objects (by area likelihood).
  void update(const Pointer& pointer, std::span<const Selectable> objects);
  const std::vector<double>& likelihoods() const { return likelihoods_; }
  // With preselection on: the object a direct click would select now.
  std::optional<int> preselected() const { return preselected_; }

  // A click of the pointer: the object it selects, if any. Remembered as selected().
  std::optional<int> click(const Pointer& pointer, std::span<const Selectable> objects);
  std::optional<int> selected() const { return selected_; }
  // Two-step's targets while it waits for the second click; empty otherwise.
  const std::vector<SelectionTarget>& targets() const;

 private:
  TwoStepSelection::Options options_;
  SelectionTechnique technique_;
  TwoStepSelection two_step_;
  bool preselect_ = true;
  std::vector<double> likelihoods_;
  std::optional<int> preselected_, selected_;
};

}  // namespace covtrack::client
