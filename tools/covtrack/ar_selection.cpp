#include "ar_selection.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

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

ArSelection::ArSelection(const RegionsModel& model, client::SelectionTechnique technique,
                         std::vector<ScriptedClick> script)
    : model_(model), script_(script.begin(), script.end()) {
  client::TwoStepSelection::Options options;
  options.indirect.screen = {client::Vec2(0, 0), client::Vec2(model.camera.width_px, model.camera.height_px)};
  session_ = client::SelectionSession(options, technique);
  std::stable_sort(script_.begin(), script_.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
}

bool ArSelection::handle(const osgGA::GUIEventAdapter& ea, osgGA::GUIActionAdapter&) {
  // Window coordinates to the image's pixels (v down, pixel centres at integers).
  const auto pixel = [&] {
    const double y = ea.getMouseYOrientation() == osgGA::GUIEventAdapter::Y_INCREASING_UPWARDS
                         ? model_.camera.height_px - ea.getY()
                         : ea.getY();
    return client::Vec2(ea.getX() - 0.5, y - 0.5);
  };
  switch (ea.getEventType()) {
    case osgGA::GUIEventAdapter::MOVE:
    case osgGA::GUIEventAdapter::DRAG:
      mouse_px_ = pixel();
      return false;
    case osgGA::GUIEventAdapter::PUSH:
      if (ea.getButton() == osgGA::GUIEventAdapter::LEFT_MOUSE_BUTTON) pending_.push_back({pixel(), ""});
      return true;
    case osgGA::GUIEventAdapter::KEYDOWN:
      if (ea.getKey() == 't') switch_technique_ = true;
      else if (ea.getKey() == 'p') switch_preselect_ = true;
      else if (ea.getKey() == ' ') pending_.push_back({std::nullopt, ""});
      else return false;
      return true;
    default:
      return false;
  }
}

client::Pointer ArSelection::pointer_at(const client::Vec2& px) const {
  return client::pointer_with_covariance(px, kMouseSigmaPx * kMouseSigmaPx * client::Mat2::Identity(),
                                         model_.confidence);
}

std::optional<client::Pointer> ArSelection::tracked_pointer(const client::TransformGraph& graph,
                                                            std::int64_t now_us) const {
  const auto& p = model_.scene.pointer;
  if (!p) return std::nullopt;
  const auto T = graph.query(model_.scene.camera.frame, p->frame, now_us);
  if (!T) return client::Pointer{client::Vec2::Zero(), {}, true};
  return client::pointer_from_projection(client::project_vertex(model_.camera, *T, p->tip_m), model_.confidence);
}

void ArSelection::click(const Click& c, const std::vector<client::Selectable>& objects,
                        const client::Pointer* tracked, std::ostream& out) {
  client::Pointer pointer;
  if (!c.target.empty()) {
    const auto& targets = session_.targets();
    const auto it = std::find_if(targets.begin(), targets.end(), [&](const client::SelectionTarget& t) {
      return model_.scene.objects[static_cast<std::size_t>(t.object)].name == c.target;
    });
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
    out << "selected " << model_.scene.objects[static_cast<std::size_t>(*picked)].name << " ("
        << technique_name(session_.technique()) << ")\n";
  } else if (!session_.targets().empty()) {
    std::vector<std::string> names;
    for (const auto& t : session_.targets()) names.push_back(model_.scene.objects[static_cast<std::size_t>(t.object)].name);
    out << fmt::format("targets: pick one of {}: {}\n", names.size(), fmt::join(names, ", "));
  } else {
    out << "selected nothing\n";
  }
}

ar::SelectionDrawing ArSelection::frame(const client::ArFrame& frame, const client::TransformGraph& graph,
                                        std::int64_t now_us, double t_s, std::ostream& out) {
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
  std::vector<client::Selectable> objects;
  for (const client::ArObjectFrame& o : frame.objects) objects.push_back(client::selectable_of(o.regions));
  const std::optional<client::Pointer> tracked = tracked_pointer(graph, now_us);
  while (!script_.empty() && script_.front().t_s <= t_s + 1e-9) {
    pending_.push_back({script_.front().at_px, script_.front().target});
    script_.pop_front();
  }
  while (!pending_.empty()) {
    click(pending_.front(), objects, tracked ? &*tracked : nullptr, out);
    pending_.pop_front();
  }
  std::optional<client::Pointer> pointer = tracked;
  if (!pointer && mouse_px_) pointer = pointer_at(*mouse_px_);
  ar::SelectionDrawing drawing;
  if (pointer) {
    session_.update(*pointer, objects);
    drawing.pointer_region = pointer->region;
  }
  drawing.selected = session_.selected();
  drawing.preselected = session_.preselected();
  drawing.targets = session_.targets();
  for (const auto& t : drawing.targets) drawing.target_names.push_back(model_.scene.objects[static_cast<std::size_t>(t.object)].name);
  return drawing;
}

}  // namespace covtrack::cli
