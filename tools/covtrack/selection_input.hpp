#pragma once
// Selection as the views take it from a user (client::SelectionSession), whatever draws
// it: the pointer is the scene's tracked pointer when it has one, else the mouse. Moving
// the mouse points, a left click (or space, for a tracked pointer) clicks, `t` switches
// direct / two-step selection, `p` preselection. Scripted clicks (--click) drive the same
// session without a window: "U,V@T" clicks the mouse at pixel (U, V) at scene time T s,
// "target:NAME@T" clicks the centre of NAME's two-step target, "pointer@T" clicks the
// tracked pointer. Every selection, every set of targets laid out and every switch is
// told on a stream (stdout), so scripts and tests can follow a session.
#include <deque>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "covtrack/client/selection_session.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/scene/scene.hpp"
#include "selection_state.hpp"

namespace covtrack::cli {

struct ScriptedClick {
  double t_s = 0;
  std::optional<client::Vec2> at_px;  // the mouse at this pixel
  std::string target;                 // else the target of this object, or "" for the tracked pointer
};

// "U,V@T", "target:NAME@T" or "pointer@T"; errors say which form was expected.
Result<ScriptedClick> parse_click(const std::string& text);

struct SelectionArgs {
  client::SelectionTechnique technique = client::SelectionTechnique::two_step;
  std::vector<std::string> clicks;
};
// --selection and --click, the same for `view` and `ar`.
void add_selection_options(CLI::App& command, SelectionArgs& args);

class SelectionInput {
 public:
  // Fails naming a scripted click that cannot be read.
  static Result<SelectionInput> create(const scene::Scene& scene, const client::Camera& camera, double confidence,
                                       const SelectionArgs& args);

  // From a window, in the image's pixels (v down, pixel centres at integers); handled at
  // the next frame. press_key is true for the keys above.
  void move_mouse(const client::Vec2& px) { mouse_px_ = px; }
  void press_mouse(const client::Vec2& px) { pending_.push_back({px, ""}); }
  bool press_key(int key);

  // One frame at scene time t_s: the tracked pointer (if the scene has one: nullopt when
  // the scene has none) and the objects; the clicks due are made and told on `out`.
  SelectionState frame(const std::optional<client::Pointer>& tracked, const std::vector<client::Selectable>& objects,
                       double t_s, std::ostream& out);

 private:
  struct Click {
    std::optional<client::Vec2> at_px;  // none: the tracked pointer
    std::string target;                 // a target by its object's name
  };
  SelectionInput(const scene::Scene& scene, double confidence, client::SelectionSession session,
                 std::vector<ScriptedClick> script);
  client::Pointer pointer_at(const client::Vec2& px) const;
  void click(const Click& c, const std::vector<client::Selectable>& objects, const client::Pointer* tracked,
             std::ostream& out);
  const std::string& name_of(int object) const;

  std::vector<std::string> names_;  // the scene's objects
  double confidence_ = 0.95;
  client::SelectionSession session_;
  std::deque<ScriptedClick> script_;
  std::deque<Click> pending_;
  std::optional<client::Vec2> mouse_px_;
  bool switch_technique_ = false, switch_preselect_ = false;
};

}  // namespace covtrack::cli
