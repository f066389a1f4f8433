#pragma once
// Static transforms in bulk: a CSV file that a scene names in `transform_tables`, one
// edge per row. toml++ reads about 10 MB/s, and a [[transform]] table is ~190 bytes: a
// 100,000-link chain took 3.3 s to load. As rows (~55 bytes each, parsed with
// std::from_chars) the whole load, graph included, takes a tenth of that
// (build/tests/tools/bench_scene_chain).
//
// The first line that is not a comment ('#') is the header, exactly kTransformTableHeader;
// each later row gives parent, child, position (m), roll/pitch/yaw (deg, R = Rz Ry Rx as
// in the scene's rotation_rpy_deg) and the six 1-sigma errors (BODY: translation, then
// rotation). No quoting: frame names hold no comma, quote or space.
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/result.hpp"
#include "covtrack/scene/scene.hpp"

namespace covtrack::scene {

inline constexpr std::string_view kTransformTableHeader =
    "parent,child,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,"
    "sigma_x_m,sigma_y_m,sigma_z_m,sigma_roll_rad,sigma_pitch_rad,sigma_yaw_rad";

// Every row as a static SceneTransform. Errors name the file, line and column; up to ten
// are reported, then the count of the rest.
Result<std::vector<SceneTransform>> parse_transform_table(std::string_view text, const std::string& source);
Result<std::vector<SceneTransform>> load_transform_table(const std::string& path);

}  // namespace covtrack::scene
