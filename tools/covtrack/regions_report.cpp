#include "regions_report.hpp"

#include <fmt/format.h>

#include "covtrack/protocol/clock.hpp"
#include "covtrack/scene/scene_graph.hpp"

namespace covtrack::cli {

Result<RegionsReport> compute_regions_report(const std::string& scene_path,
                                             client::ProjectionMethod method,
                                             client::Propagation propagation, double confidence) {
  auto scene = scene::load_scene(scene_path);
  if (!scene) return std::unexpected(scene.error());
  auto camera = client::load_camera(scene->camera.calibration_path);
  if (!camera) return std::unexpected(camera.error());
  auto objects = scene::hull_objects(*scene);
  if (!objects) return fail(fmt::format("{}: {}", scene_path, objects.error().message));

  const std::int64_t query_time_us = covtrack::now_us();
  client::TransformGraph graph(propagation);
  if (auto r = scene::add_scene_transforms(*scene, graph, query_time_us); !r)
    return fail(fmt::format("{}: {}", scene_path, r.error().message));

  RegionsReport report{*camera, scene->camera.frame,
                       confidence > 0 ? confidence : scene->camera.confidence, {}};
  client::ObjectRegionOptions options;
  options.projection.method = method;
  options.regions.confidence = report.confidence;
  options.assessment = {client::largest_semi_axis_px(report.confidence), client::max_value()};
  for (scene::HullObject& o : *objects) {
    const auto T = graph.query(report.camera_frame, o.frame, query_time_us);
    if (!T) return fail(fmt::format("{}: object {}: {}", scene_path, o.name, T.error().message));
    client::ObjectRegions regions = client::compute_object_regions(*camera, *T, o.hull_vertices_m, options);
    report.objects.push_back({o.name, o.frame, std::move(o.hull_vertices_m), std::move(regions)});
  }
  return report;
}

}  // namespace covtrack::cli
