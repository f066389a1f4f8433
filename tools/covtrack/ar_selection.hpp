#pragma once
// `covtrack ar`'s selection (client::SelectionSession): the pointer is the mouse, or the
// scene's tracked pointer (its tip projected with its error) when the scene has one. In
// the window: moving the mouse points, the left button (or space, for a tracked pointer)
// clicks, `t` switches direct / two-step selection, `p` preselection. Scripted clicks
// (--click) drive the same session without a window: "U,V@T" clicks the mouse at pixel
// (U, V) at scene time T s, "target:NAME@T" clicks the centre of NAME's two-step target,
// "pointer@T" clicks the tracked pointer. Every selection, and every set of targets laid
// out, is told on stdout, so scripts and tests can follow a session.
#include <deque>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <osgGA/GUIEventHandler>

#include "covtrack/client/selection_session.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/osg/ar_scene.hpp"
#include "covtrack/protocol/result.hpp"
#include "regions_report.hpp"

namespace covtrack::cli {

struct ScriptedClick {
  double t_s = 0;
  std::optional<client::Vec2> at_px;  // the mouse at this pixel
  std::string target;                 // else the target of this object, or "" for the tracked pointer
};

// "U,V@T", "target:NAME@T" or "pointer@T"; errors say which form was expected.
Result<ScriptedClick> parse_click(const std::string& text);

class ArSelection : public osgGA::GUIEventHandler {
 public:
  ArSelection(const RegionsModel& model, client::SelectionTechnique technique, std::vector<ScriptedClick> script);

  // The window's mouse and keys.
  bool handle(const osgGA::GUIEventAdapter& event, osgGA::GUIActionAdapter&) override;

  // One frame at scene time t_s: the pointer now, the clicks due, what to draw. What is
  // selected or laid out is told on `out`.
  ar::SelectionDrawing frame(const client::ArFrame& frame, const client::TransformGraph& graph, std::int64_t now_us,
                             double t_s, std::ostream& out);

 private:
  struct Click {
    std::optional<client::Vec2> at_px;  // none: the tracked pointer
    std::string target;                 // a target by its object's name
  };
  client::Pointer pointer_at(const client::Vec2& px) const;
  std::optional<client::Pointer> tracked_pointer(const client::TransformGraph& graph, std::int64_t now_us) const;
  void click(const Click& c, const std::vector<client::Selectable>& objects, const client::Pointer* tracked,
             std::ostream& out);

  const RegionsModel& model_;
  client::SelectionSession session_;
  std::deque<ScriptedClick> script_;
  std::deque<Click> pending_;  // from the window, handled at the next frame
  std::optional<client::Vec2> mouse_px_;
  bool switch_technique_ = false, switch_preselect_ = false;
};

}  // namespace covtrack::cli
