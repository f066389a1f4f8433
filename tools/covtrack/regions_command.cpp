// `covtrack regions SCENE`: the registration error a setup will have, before anyone builds
// it. Per object: the mean pixel and 2x2 covariance of every 3-D hull vertex, the outer and
// inner regions, the assessment and the flags; as text, JSON (--json) or a picture (--png).
#include <iostream>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/scene/scene.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"

namespace covtrack::cli {
namespace {

struct RegionsArgs {
  std::string scene_path;
  bool json = false;
  std::string png_path;
  bool print_schema = false;
  client::ProjectionMethod method = client::ProjectionMethod::unscented;
  client::Propagation propagation = client::Propagation::LowestCommonAncestor;
  double confidence = 0;  // 0: the scene's
};

nlohmann::json polygon_json(const client::Polygon& polygon) {
  nlohmann::json points = nlohmann::json::array();
  for (const client::Vec2& p : polygon) points.push_back({p.x(), p.y()});
  return points;
}

nlohmann::json object_json(const RegionsReport::Object& o) {
  nlohmann::json vertices = nlohmann::json::array();
  for (std::size_t i = 0; i < o.regions.vertices.size(); ++i) {
    const client::ProjectedVertex& v = o.regions.vertices[i];
    const Vec3& p = o.hull_vertices_m[i];
    const client::Mat2& c = v.covariance_px2;
    nlohmann::json vertex = {{"vertex_m", {p.x(), p.y(), p.z()}},
                             {"mean_px", nullptr},
                             {"covariance_px2", nullptr},
                             {"depth_m", v.depth_m},
                             {"depth_sigma_m", v.depth_sigma_m},
                             {"flags", flag_names(v.flags)}};
    if (v.flags.usable()) {  // otherwise there is no pixel, or no covariance, to give
      vertex["mean_px"] = {v.mean_px.x(), v.mean_px.y()};
      vertex["covariance_px2"] = {{c(0, 0), c(0, 1)}, {c(1, 0), c(1, 1)}};
    }
    vertices.push_back(vertex);
  }
  const double a = o.regions.assessment;
  return {{"name", o.name},
          {"frame", o.frame},
          {"valid", o.regions.valid},
          {"assessment_px", std::isfinite(a) ? nlohmann::json(a) : nlohmann::json(nullptr)},
          {"flags", flag_names(o.regions.flags)},
          {"vertices", vertices},
          {"screen_hull", o.regions.hull},
          {"outer_scale", o.regions.outer_scale},
          {"outer_px", polygon_json(o.regions.outer)},
          {"inner_px", polygon_json(o.regions.inner)}};
}

std::string polygon_text(const client::Polygon& polygon) {
  std::string s;
  for (const client::Vec2& p : polygon) s += fmt::format(" ({:.1f}, {:.1f})", p.x(), p.y());
  return s;
}

void print_text(const RegionsReport& report) {
  fmt::print("camera {} ({}x{} px), {:.0f}% confidence, error = largest semi-axis\n",
             report.camera_frame, report.camera.width_px, report.camera.height_px,
             100 * report.confidence);
  for (const RegionsReport::Object& o : report.objects) {
    const client::ObjectRegions& r = o.regions;
    const auto flags = flag_names(r.flags);
    fmt::print("\nobject {} (frame {}): {}{}\n", o.name, o.frame,
               r.valid ? fmt::format("error {:.2f} px", r.assessment) : std::string("NO REGION"),
               flags.empty() ? "" : fmt::format(" [{}]", fmt::join(flags, ", ")));
    for (std::size_t i = 0; i < r.vertices.size(); ++i) {
      const client::ProjectedVertex& v = r.vertices[i];
      const client::Mat2& c = v.covariance_px2;
      if (!v.flags.usable()) {
        fmt::print("  vertex {:2} no pixel [{}]  depth {:.2f} m\n", i, fmt::join(flag_names(v.flags), ", "), v.depth_m);
        continue;
      }
      fmt::print("  vertex {:2} pixel ({:7.1f}, {:7.1f})  cov px^2 [{:.3g} {:.3g}; {:.3g} {:.3g}]  depth {:.2f} m\n",
                 i, v.mean_px.x(), v.mean_px.y(), c(0, 0), c(0, 1), c(1, 0), c(1, 1), v.depth_m);
    }
    if (!r.valid) continue;
    fmt::print("  outer ({} points, ellipses at {:.2f} sigma: the whole object at {:.0f}%):{}\n", r.outer.size(),
               r.outer_scale, 100 * report.confidence, polygon_text(r.outer));
    if (r.hull.size() < 3)
      fmt::print("  inner: none (the object covers no area on the screen)\n");
    else if (r.inner.empty())
      fmt::print("  inner: empty (the error swamps the object)\n");
    else
      fmt::print("  inner ({} points):{}\n", r.inner.size(), polygon_text(r.inner));
  }
}

int run_regions(const RegionsArgs& args) {
  if (args.print_schema) {
    std::cout << scene::scene_schema_markdown();
    return 0;
  }
  if (args.scene_path.empty()) {
    std::cerr << "covtrack regions: a SCENE file is required (or --print-schema)\n";
    return 2;
  }
  const auto model = load_regions_model(args.scene_path, args.confidence);
  if (!model) {
    std::cerr << "covtrack regions: " << model.error().message << "\n";
    return 2;
  }
  // Tracked transforms take their scene values as reports measured now: no staleness.
  const std::int64_t now = covtrack::now_us();
  client::TransformGraph graph(args.propagation);
  if (auto r = scene::add_scene_transforms(model->scene, graph, now); !r) {
    std::cerr << "covtrack regions: " << args.scene_path << ": " << r.error().message << "\n";
    return 2;
  }
  const auto report = compute_regions(*model, graph, now, args.method);
  if (!report) {
    std::cerr << "covtrack regions: " << args.scene_path << ": " << report.error().message << "\n";
    return 2;
  }
  if (args.json) {
    nlohmann::json objects = nlohmann::json::array();
    for (const auto& o : report->objects) objects.push_back(object_json(o));
    std::cout << nlohmann::json{{"scene", args.scene_path},
                                {"camera_frame", report->camera_frame},
                                {"confidence", report->confidence},
                                {"objects", objects}}
                     .dump(2)
              << "\n";
  } else {
    print_text(*report);
  }
  if (!args.png_path.empty()) {
    cv::Mat image(report->camera.height_px, report->camera.width_px, CV_8UC3, cv::Scalar(40, 40, 40));
    draw_regions(image, *report);
    if (auto r = write_png(image, args.png_path); !r) {
      std::cerr << "covtrack regions: " << r.error().message << "\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace

void add_regions_command(CLI::App& app) {
  auto args = std::make_shared<RegionsArgs>();
  auto* cmd = app.add_subcommand("regions", "Screen error regions of a scene's objects (offline)");
  cmd->add_option("SCENE", args->scene_path, "Scene file (config/scene_schema.md)");
  cmd->add_flag("--json,-j", args->json, "One JSON document instead of text");
  cmd->add_option("--png", args->png_path, "Also draw the regions into this PNG file");
  cmd->add_flag("--print-schema", args->print_schema, "Print the scene file reference (Markdown)");
  const std::map<std::string, client::ProjectionMethod> methods = {
      {"unscented", client::ProjectionMethod::unscented}, {"linear", client::ProjectionMethod::linear}};
  cmd->add_option("--method", args->method, "Vertex projection: unscented or linear")
      ->transform(program::one_of(methods));
  const std::map<std::string, client::Propagation> propagations = {
      {"lca", client::Propagation::LowestCommonAncestor},
      {"osgar-root", client::Propagation::OsgarRoot},
      {"osgar-matrix16", client::Propagation::OsgarMatrix16}};
  cmd->add_option("--propagation", args->propagation,
                  "lca (exact, default); osgar-root or osgar-matrix16: osgAR's propagation from the root (docs/background.md), "
                  "kept to compare against: it gives objects attached to a tracked frame an error they do not have")
      ->transform(program::one_of(propagations));
  cmd->add_option("--confidence", args->confidence, "Confidence of the regions (default: the scene's)")
      ->check(program::in_range(0.5, 0.9999));
  cmd->callback([args] {
    if (const int code = run_regions(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
