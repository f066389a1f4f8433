#include "covtrack/client/selection_session.hpp"

namespace covtrack::client {

SelectionSession::SelectionSession(TwoStepSelection::Options options, SelectionTechnique technique)
    : options_(options), technique_(technique), two_step_(options) {}

void SelectionSession::set_technique(SelectionTechnique technique) {
  technique_ = technique;
  two_step_ = TwoStepSelection(options_);
}

void SelectionSession::update(const Pointer& pointer, std::span<const Selectable> objects) {
  likelihoods_ = likelihoods_by_area(pointer, objects);
  preselected_.reset();
  if (preselect_) preselected_ = select_direct(likelihoods_, objects, options_.min_likelihood).selected;
}

std::optional<int> SelectionSession::click(const Pointer& pointer, std::span<const Selectable> objects) {
  std::optional<int> picked;
  if (technique_ == SelectionTechnique::direct)
    picked = select_direct(likelihoods_by_area(pointer, objects), objects, options_.min_likelihood).selected;
  else
    picked = two_step_.click(pointer, objects);
  if (picked) selected_ = picked;
  return picked;
}

const std::vector<SelectionTarget>& SelectionSession::targets() const {
  static const std::vector<SelectionTarget> none;
  return technique_ == SelectionTechnique::two_step && two_step_.step() == TwoStepSelection::Step::pick_object
             ? two_step_.targets()
             : none;
}

}  // namespace covtrack::client
