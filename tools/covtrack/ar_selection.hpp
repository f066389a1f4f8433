#pragma once
// `covtrack ar`'s selection: the window's mouse and keys into a SelectionInput
// (selection_input.hpp says what they do), the scene's tracked pointer projected with its
// error, and what the session shows as the ArScene draws it.
#include <optional>
#include <ostream>

#include <osgGA/GUIEventHandler>

#include "covtrack/client/transform_graph.hpp"
#include "covtrack/osg/ar_scene.hpp"
#include "regions_report.hpp"
#include "selection_input.hpp"

namespace covtrack::cli {

class ArSelection : public osgGA::GUIEventHandler {
 public:
  ArSelection(const RegionsModel& model, SelectionInput input) : model_(model), input_(std::move(input)) {}

  // The window's mouse and keys.
  bool handle(const osgGA::GUIEventAdapter& event, osgGA::GUIActionAdapter&) override;

  // One frame at scene time t_s: the pointer now, the clicks due, what to draw. What is
  // selected or laid out is told on `out`.
  ar::SelectionDrawing frame(const client::ArFrame& frame, const client::TransformGraph& graph, std::int64_t now_us,
                             double t_s, std::ostream& out);

 private:
  std::optional<client::Pointer> tracked_pointer(const client::TransformGraph& graph, std::int64_t now_us) const;

  const RegionsModel& model_;
  SelectionInput input_;
};

}  // namespace covtrack::cli
