#include "regions_report.hpp"

#include <fmt/format.h>

namespace covtrack::cli {

Result<RegionsModel> load_regions_model(const std::string& scene_path, double confidence) {
  auto scene = scene::load_scene(scene_path);
  if (!scene) return std::unexpected(scene.error());
  auto camera = client::load_camera(scene->camera.calibration_path);
  if (!camera) return std::unexpected(camera.error());
  auto objects = scene::hull_objects(*scene);
  if (!objects) return fail(fmt::format("{}: {}", scene_path, objects.error().message));
  const double p = confidence > 0 ? confidence : scene->camera.confidence;
  return RegionsModel{scene_path, std::move(*scene), *camera, p, std::move(*objects)};
}

std::vector<std::string> flag_names(const client::ProjectionFlags& f) {
  std::vector<std::string> names;
  if (f.behind_camera) names.push_back("behind_camera");
  if (f.sigma_point_behind_camera) names.push_back("sigma_point_behind_camera");
  if (f.rotation_too_uncertain) names.push_back("rotation_too_uncertain");
  if (f.unbounded) names.push_back("unbounded");
  if (f.covariance_repaired) names.push_back("covariance_repaired");
  if (f.past_distortion_fold) names.push_back("past_distortion_fold");
  if (f.not_finite) names.push_back("not_finite");
  if (f.depth_nonlinear) names.push_back("depth_nonlinear");
  return names;
}

Result<RegionsReport> compute_regions(const RegionsModel& model, const client::TransformGraph& graph,
                                      std::int64_t time_us, client::ProjectionMethod method) {
  RegionsReport report{model.camera, model.scene.camera.frame, model.confidence, {}, std::nullopt};
  client::ObjectRegionOptions options;
  options.projection.method = method;
  options.regions.confidence = model.confidence;
  options.assessment = {client::largest_semi_axis_px(model.confidence), client::max_value()};
  for (const scene::HullObject& o : model.objects) {
    const auto T = graph.query(report.camera_frame, o.frame, time_us);
    if (!T) return fail(fmt::format("object {}: {}", o.name, T.error().message));
    report.objects.push_back({o.name, o.frame, o.hull_vertices_m,
                              client::compute_object_regions(model.camera, *T, o.hull_vertices_m, options)});
  }
  if (const auto& pointer = model.scene.pointer) {
    const auto T = graph.query(report.camera_frame, pointer->frame, time_us);
    if (!T) return fail(fmt::format("pointer: {}", T.error().message));
    report.pointer_tip = client::project_vertex(model.camera, *T, pointer->tip_m, options.projection);
  }
  return report;
}

std::vector<client::Selectable> selectables_of(const RegionsReport& report) {
  std::vector<client::Selectable> objects;
  for (const RegionsReport::Object& o : report.objects) objects.push_back(client::selectable_of(o.regions));
  return objects;
}

}  // namespace covtrack::cli
