#include "selection_input.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "covtrack/program/command_line.hpp"
#include "view_labels.hpp"

namespace covtrack::cli {
namespace {

// The mouse is precise to about a pixel: its region is a small circle (sigma 1 px).
constexpr double kMouseSigmaPx = 1.0;

std::string technique_name(client::SelectionTechnique t) {
  return t == client::SelectionTechnique::direct ? "direct" : "two-step";
}

}  // namespace

Result<ScriptedClick> parse_click(const std::string& text) {
  const auto at = text.rfind('@');
  const auto form = [&] {
    return fail(fmt::format("--click '{}': expected U,V@T (pixel, scene seconds), target:NAME@T or pointer@T", text));
  };
  if (at == std::string::npos) return form();
  ScriptedClick c;
  const std::string what = text.substr(0, at), when = text.substr(at + 1);
  if (std::from_chars(when.data(), when.data() + when.size(), c.t_s).ptr != when.data() + when.size() ||
      !(c.t_s >= 0))
    return form();
  if (what == "pointer") return c;
  if (what.rfind("target:", 0) == 0 && what.size() > 7) {
    c.target = what.substr(7);
    return c;
  }
  const auto comma = what.find(',');
  double u = 0, v = 0;
  if (comma == std::string::npos ||
      std::from_chars(what.data(), what.data() + comma, u).ptr != what.data() + comma ||
      std::from_chars(what.data() + comma + 1, what.data() + what.size(), v).ptr != what.data() + what.size() ||
      !std::isfinite(u) || !std::isfinite(v))
    return form();
  c.at_px = client::Vec2(u, v);
  return c;
}

void add_selection_options(CLI::App& command, SelectionArgs& args) {
  const std::map<std::string, client::SelectionTechnique> techniques = {
      {"direct", client::SelectionTechnique::direct}, {"two-step", client::SelectionTechnique::two_step}};
  command.add_option("--selection", args.technique,
                     "direct (a click picks the most likely object) or two-step (a click on several lays out a "
                     "target each); `t` switches in the window, `p` switches preselection")
      ->transform(program::one_of(techniques));
  command.add_option("--click", args.clicks,
                     "A scripted click: U,V@T (the mouse at pixel U,V at scene second T), target:NAME@T (NAME's "
                     "two-step target) or pointer@T (the scene's tracked pointer); repeat for a session. Selections "
                     "are told on stdout");
}

Result<SelectionInput> SelectionInput::create(const scene::Scene& scene, const client::Camera& camera,
                                              double confidence, const SelectionArgs& args) {
  std::vector<ScriptedClick> script;
  for (const std::string& text : args.clicks) {
    auto click = parse_click(text);
    if (!click) return std::unexpected(click.error());
    script.push_back(*click);
  }
  std::stable_sort(script.begin(), script.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  client::TwoStepSelection::Options options;
  options.indirect.screen = {client::Vec2(0, 0), client::Vec2(camera.width_px, camera.height_px)};
  // Targets wide enough for the longest name, at the labels' font: a cut name cannot be
  // told apart from another.
  for (const scene::SceneObject& o : scene.objects)
    options.indirect.target_size_px.x() = std::max(options.indirect.target_size_px.x(), label_box_px(o.name).x());
  return SelectionInput(scene, confidence, client::SelectionSession(options, args.technique), std::move(script));
}

SelectionInput::SelectionInput(const scene::Scene& scene, double confidence, client::SelectionSession session,
                               std::vector<ScriptedClick> script)
    : confidence_(confidence), session_(std::move(session)), script_(script.begin(), script.end()) {
  for (const scene::SceneObject& o : scene.objects) names_.push_back(o.name);
}

bool SelectionInput::press_key(int key) {
  if (key == 't') switch_technique_ = true;
  else if (key == 'p') switch_preselect_ = true;
  else if (key == ' ') pending_.push_back({std::nullopt, ""});
  else return false;
  return true;
}

client::Pointer SelectionInput::pointer_at(const client::Vec2& px) const {
  return client::pointer_with_covariance(px, kMouseSigmaPx * kMouseSigmaPx * client::Mat2::Identity(), confidence_);
}

const std::string& SelectionInput::name_of(int object) const { return names_[static_cast<std::size_t>(object)]; }

void SelectionInput::click(const Click& c, const std::vector<client::Selectable>& objects,
                           const client::Pointer* tracked, std::ostream& out) {
  client::Pointer pointer;
  if (!c.target.empty()) {
    const auto& targets = session_.targets();
    const auto it = std::find_if(targets.begin(), targets.end(),
                                 [&](const client::SelectionTarget& t) { return name_of(t.object) == c.target; });
    if (it == targets.end()) {
      out << "click: no target of '" << c.target << "' is shown\n";
      return;
    }
    pointer = pointer_at(it->box.center());
  } else if (c.at_px) {
    mouse_px_ = *c.at_px;
    pointer = pointer_at(*c.at_px);
  } else if (tracked) {
    pointer = *tracked;
  } else {
    out << "click: the scene has no tracked pointer\n";
    return;
  }
  const auto picked = session_.click(pointer, objects);
  if (picked) {
    out << "selected " << name_of(*picked) << " (" << technique_name(session_.technique()) << ")\n";
  } else if (!session_.targets().empty()) {
    std::vector<std::string> names;
    for (const auto& t : session_.targets()) names.push_back(name_of(t.object));
    out << fmt::format("targets: pick one of {}: {}\n", names.size(), fmt::join(names, ", "));
  } else {
    out << "selected nothing\n";
  }
}

SelectionState SelectionInput::frame(const std::optional<client::Pointer>& tracked,
                                     const std::vector<client::Selectable>& objects, double t_s, std::ostream& out) {
  if (switch_technique_) {
    session_.set_technique(session_.technique() == client::SelectionTechnique::direct
                               ? client::SelectionTechnique::two_step
                               : client::SelectionTechnique::direct);
    out << "selection: " << technique_name(session_.technique()) << "\n";
  }
  if (switch_preselect_) {
    session_.set_preselect(!session_.preselect());
    out << "preselection: " << (session_.preselect() ? "on" : "off") << "\n";
  }
  switch_technique_ = switch_preselect_ = false;
  while (!script_.empty() && script_.front().t_s <= t_s + 1e-9) {
    pending_.push_back({script_.front().at_px, script_.front().target});
    script_.pop_front();
  }
  while (!pending_.empty()) {
    click(pending_.front(), objects, tracked ? &*tracked : nullptr, out);
    pending_.pop_front();
  }
  SelectionState state;
  state.pointer = tracked;
  if (!state.pointer && mouse_px_) state.pointer = pointer_at(*mouse_px_);
  if (state.pointer) {
    session_.update(*state.pointer, objects);
    state.likelihoods = session_.likelihoods();
  }
  state.selected = session_.selected();
  state.preselected = session_.preselected();
  state.preselect = session_.preselect();
  state.targets = session_.targets();
  for (const auto& t : state.targets) state.target_names.push_back(name_of(t.object));
  state.technique_name = technique_name(session_.technique());
  out << std::flush;  // a script following the session reads each line as it happens
  return state;
}

}  // namespace covtrack::cli
