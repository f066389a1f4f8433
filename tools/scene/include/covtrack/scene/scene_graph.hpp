#pragma once
// A scene's transforms as a client TransformGraph, and its objects reduced to their 3-D
// hull vertices: what `covtrack regions` and `covtrack view` compute regions from.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/client/transform_graph.hpp"
#include "covtrack/scene/scene.hpp"

namespace covtrack::scene {

// Adds every transform of the scene to `graph`, then its fused frames. Tracked ones are bound to their streams
// with their motion bounds. With `reports_at_us`, each tracked edge also receives its
// scene value as a report measured at that time: the offline "what if the tracker
// reports this" case. Without it, tracked edges stay LOST until their streams report.
Result<void> add_scene_transforms(const Scene& scene, client::TransformGraph& graph,
                                  std::optional<std::int64_t> reports_at_us);

// Offline scripts: every transform with keyframes reports its value at scene_time_s
// (scripted_value), measured at now_us. Edges without keyframes are left alone.
Result<void> report_keyframes(const Scene& scene, client::TransformGraph& graph,
                              double scene_time_s, std::int64_t now_us);

struct HullObject {
  std::string name;
  std::string frame;
  std::vector<Vec3> hull_vertices_m;  // the 3-D hull vertices of the object, its frame
};

// Each object's 3-D hull, once. Fails naming the object if its vertices cannot form one.
Result<std::vector<HullObject>> hull_objects(const Scene& scene);

}  // namespace covtrack::scene
