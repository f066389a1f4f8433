#pragma once
// What a session of selection with a user shows in one frame (selection_input.hpp makes
// it; the views draw it).
#include <optional>
#include <string>
#include <vector>

#include "covtrack/client/selection.hpp"

namespace covtrack::cli {

// What the session shows this frame.
struct SelectionState {
  std::optional<client::Pointer> pointer;  // the tracked pointer, else the mouse once it has moved
  std::vector<double> likelihoods;         // per object, by area, with a pointer
  std::optional<int> selected, preselected;
  bool preselect = true;  // preselection on (`p`)
  std::vector<client::SelectionTarget> targets;  // two-step's, waiting for the second click
  std::vector<std::string> target_names;         // one per target
  std::string technique_name;                    // "direct" or "two-step"
};

}  // namespace covtrack::cli
