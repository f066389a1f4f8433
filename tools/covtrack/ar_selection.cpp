#include "ar_selection.hpp"

namespace covtrack::cli {

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
      input_.move_mouse(pixel());
      return false;
    case osgGA::GUIEventAdapter::PUSH:
      if (ea.getButton() == osgGA::GUIEventAdapter::LEFT_MOUSE_BUTTON) input_.press_mouse(pixel());
      return true;
    case osgGA::GUIEventAdapter::KEYDOWN:
      return input_.press_key(ea.getKey());
    default:
      return false;
  }
}

std::optional<client::Pointer> ArSelection::tracked_pointer(const client::TransformGraph& graph,
                                                            std::int64_t now_us) const {
  const auto& p = model_.scene.pointer;
  if (!p) return std::nullopt;
  const auto T = graph.query(model_.scene.camera.frame, p->frame, now_us);
  if (!T) return client::Pointer{client::Vec2::Zero(), {}, true};
  return client::pointer_from_projection(client::project_vertex(model_.camera, *T, p->tip_m), model_.confidence);
}

ar::SelectionDrawing ArSelection::frame(const client::ArFrame& frame, const client::TransformGraph& graph,
                                        std::int64_t now_us, double t_s, std::ostream& out) {
  std::vector<client::Selectable> objects;
  for (const client::ArObjectFrame& o : frame.objects) objects.push_back(client::selectable_of(o.regions));
  SelectionState state = input_.frame(tracked_pointer(graph, now_us), objects, t_s, out);
  ar::SelectionDrawing drawing;
  if (state.pointer) drawing.pointer_region = state.pointer->region;
  drawing.selected = state.selected;
  drawing.preselected = state.preselected;
  drawing.targets = std::move(state.targets);
  drawing.target_names = std::move(state.target_names);
  return drawing;
}

}  // namespace covtrack::cli
