#pragma once
// Shared by the tests that run the `covtrack` command: a run of it (support/run_command.hpp
// keeps its output and exit code), containment in a polygon as `covtrack regions --json` prints it, and a scene for
// scripted selection.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_command.hpp"

namespace covtrack::testing {

// `covtrack ARGS`, with `env_prefix` (e.g. "env -u DISPLAY") before it.
inline CliRun run_covtrack(const std::string& args, const std::string& env_prefix = "") {
  return run_command(env_prefix + " " + std::string(COVTRACK_CLI) + " " + args);
}

// Inside a counter-clockwise convex polygon [[u, v], ...] (in u, v arithmetic), or within
// `tolerance` px of it.
inline bool json_polygon_contains(const nlohmann::json& polygon, double u, double v, double tolerance) {
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double au = polygon[i][0], av = polygon[i][1];
    const double bu = polygon[(i + 1) % n][0], bv = polygon[(i + 1) % n][1];
    if ((bu - au) * (v - av) - (bv - av) * (u - au) < -tolerance * std::hypot(bu - au, bv - av)) return false;
  }
  return n >= 3;
}

// Two crates side by side whose outer regions overlap, for scripted clicks: the scene
// file, a pixel "U,V" in both outer regions, and the middle of the left crate.
struct CratesScene {
  std::string path, in_both_px, left_middle_px;
  nlohmann::json regions;  // `covtrack regions --json`
};

inline std::optional<CratesScene> write_crates_scene(const std::filesystem::path& dir) {
  CratesScene c{(dir / "crates.toml").string(), "", "", {}};
  std::ofstream(c.path) << "[camera]\nframe = \"camera\"\ncalibration = \"" COVTRACK_SOURCE_DIR
                           "/config/cameras/rendered_640x480.yml\"\n"
                           "[[transform]]\nparent = \"camera\"\nchild = \"left\"\nposition_m = [-0.046, 0, 0.5]\n"
                           "sigma_m = [0.003, 0.003, 0.003]\nsigma_rad = [0.01, 0.01, 0.01]\n"
                           "[[transform]]\nparent = \"camera\"\nchild = \"right\"\nposition_m = [0.046, 0, 0.5]\n"
                           "sigma_m = [0.003, 0.003, 0.003]\nsigma_rad = [0.01, 0.01, 0.01]\n"
                           "[[object]]\nname = \"left_crate\"\nframe = \"left\"\nbox_m = [0.08, 0.06, 0.04]\n"
                           "[[object]]\nname = \"right_crate\"\nframe = \"right\"\nbox_m = [0.08, 0.06, 0.04]\n";
  const CliRun regions = run_covtrack("regions " + c.path + " --json");
  if (regions.exit_code != 0) return std::nullopt;
  c.regions = nlohmann::json::parse(regions.out, nullptr, false);
  if (c.regions.is_discarded()) return std::nullopt;
  const nlohmann::json& left = c.regions["objects"][0]["outer_px"];
  const nlohmann::json& right = c.regions["objects"][1]["outer_px"];
  for (int v = 0; v < 480 && c.in_both_px.empty(); ++v)
    for (int u = 0; u < 640 && c.in_both_px.empty(); ++u)
      if (json_polygon_contains(left, u, v, 0) && json_polygon_contains(right, u, v, 0))
        c.in_both_px = std::to_string(u) + "," + std::to_string(v);
  if (c.in_both_px.empty()) return std::nullopt;  // the test needs them to overlap
  double cu = 0, cv = 0;
  const nlohmann::json& inner = c.regions["objects"][0]["inner_px"];
  for (const auto& p : inner) cu += p[0].get<double>(), cv += p[1].get<double>();
  c.left_middle_px = std::to_string(cu / inner.size()) + "," + std::to_string(cv / inner.size());
  return c;
}

}  // namespace covtrack::testing
