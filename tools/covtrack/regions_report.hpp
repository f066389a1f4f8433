#pragma once
// A scene's objects through its camera: the regions `covtrack regions` prints and draws.
// Tracked transforms take their scene values as fresh reports (the offline question).
#include <string>
#include <vector>

#include "covtrack/client/regions.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::cli {

struct RegionsReport {
  struct Object {
    std::string name;
    std::string frame;
    std::vector<Vec3> hull_vertices_m;  // same order as regions.vertices
    client::ObjectRegions regions;
  };
  client::Camera camera;
  std::string camera_frame;
  double confidence = 0.95;
  std::vector<Object> objects;
};

// confidence 0 takes the scene's. Errors name the scene file (and line, for its syntax).
Result<RegionsReport> compute_regions_report(const std::string& scene_path,
                                             client::ProjectionMethod method,
                                             client::Propagation propagation, double confidence);

}  // namespace covtrack::cli
