// The transform graph, cameras and screen error regions: covtrack.TransformGraph,
// UncertainPose, Camera, ObjectRegions, object_regions(), and covtrack.Scene, which loads
// a scene file the way `covtrack regions` does and computes its regions with the same
// code (tools/covtrack/regions_report.hpp), so both give the same numbers.
#include <cmath>
#include <limits>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "covtrack/client/regions.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/protocol/clock.hpp"
#include "log_columns.hpp"
#include "regions_report.hpp"

namespace covtrack::python {
namespace {

using client::TransformGraph;
using client::UncertainPose;
using ObjectResult = cli::RegionsReport::Object;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

client::Propagation propagation_of(const std::string& name) {
  if (name == "lca") return client::Propagation::LowestCommonAncestor;
  if (name == "osgar-root") return client::Propagation::OsgarRoot;
  if (name == "osgar-matrix16") return client::Propagation::OsgarMatrix16;
  throw py::value_error("propagation must be 'lca', 'osgar-root' or 'osgar-matrix16', not '" + name + "'");
}

client::ProjectionMethod method_of(const std::string& name) {
  if (name == "unscented") return client::ProjectionMethod::unscented;
  if (name == "linear") return client::ProjectionMethod::linear;
  throw py::value_error("method must be 'unscented' or 'linear', not '" + name + "'");
}

// A 4x4 homogeneous matrix as a Pose; it must be a rigid transform.
Pose rigid(const Eigen::Matrix4d& m) {
  const Mat3 R = m.topLeftCorner<3, 3>();
  if (!m.allFinite() || (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      R.determinant() < 0 || (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12)
    throw py::value_error("not a rigid transform: the 4x4 matrix needs a rotation (orthonormal, det +1) "
                          "and a last row of 0 0 0 1");
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

py::array_t<double> points_array(const client::Polygon& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{2}});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    a(i, 0) = points[i].x();
    a(i, 1) = points[i].y();
  }
  return out;
}

// Each vertex's mean pixel or 2x2 covariance; NaN where the vertex has none (not usable,
// as `covtrack regions --json` gives null).
py::array_t<double> vertex_means(const ObjectResult& o) {
  const auto& vs = o.regions.vertices;
  py::array_t<double> out({static_cast<py::ssize_t>(vs.size()), py::ssize_t{2}});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < vs.size(); ++i)
    for (int k = 0; k < 2; ++k) a(i, k) = vs[i].flags.usable() ? vs[i].mean_px(k) : kNaN;
  return out;
}

py::array_t<double> vertex_covariances(const ObjectResult& o) {
  const auto& vs = o.regions.vertices;
  py::array_t<double> out({static_cast<py::ssize_t>(vs.size()), py::ssize_t{2}, py::ssize_t{2}});
  auto a = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < vs.size(); ++i)
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c) a(i, r, c) = vs[i].flags.usable() ? vs[i].covariance_px2(r, c) : kNaN;
  return out;
}

client::ObjectRegionOptions region_options(double confidence, client::ProjectionMethod method) {
  client::ObjectRegionOptions options;  // as cli::compute_regions sets them
  options.projection.method = method;
  options.regions.confidence = confidence;
  options.assessment = {client::largest_semi_axis_px(confidence), client::max_value()};
  return options;
}

// A Scene: the loaded model, as `covtrack regions` loads it.
struct PyScene {
  cli::RegionsModel model;

  std::shared_ptr<TransformGraph> graph(bool live, const std::string& propagation,
                                        std::optional<std::int64_t> reports_at_us) const {
    auto graph = std::make_shared<TransformGraph>(propagation_of(propagation));
    std::optional<std::int64_t> at;
    if (!live) at = reports_at_us.value_or(now_us());
    check(scene::add_scene_transforms(model.scene, *graph, at));
    return graph;
  }

  std::vector<ObjectResult> regions(std::shared_ptr<TransformGraph> graph, std::optional<std::int64_t> time_us,
                                    const std::string& method, const std::string& propagation) const {
    // As `covtrack regions`: tracked edges report their scene values at the query time.
    const std::int64_t now = time_us.value_or(now_us());
    if (!graph) graph = this->graph(false, propagation, now);
    return value_or_raise(cli::compute_regions(model, *graph, now, method_of(method))).objects;
  }
};

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<UncertainPose>(m, "UncertainPose", "A transform with its BODY covariance, as a graph query gives it")
      .def_property_readonly("matrix", [](const UncertainPose& u) { return Eigen::Matrix4d(u.T.matrix()); })
      .def_property_readonly("position", [](const UncertainPose& u) { return Vec3(u.T.translation()); })
      .def_property_readonly("quaternion", [](const UncertainPose& u) { return quaternion_wxyz(u.T); })
      .def_property_readonly("covariance", [](const UncertainPose& u) { return Mat6(u.covariance); })
      .def_readonly("unbounded", &UncertainPose::unbounded,
                    "a LOST or never reported edge on the path: the covariance means nothing");

  py::class_<client::Camera>(m, "Camera", "A pinhole camera with OpenCV's k1 k2 p1 p2 k3 distortion")
      .def_static("load", [](const std::string& path) { return value_or_raise(client::load_camera(path)); },
                  py::arg("path"), "Reads a camera calibration: OpenCV (camera_matrix, distortion_coefficients, ...) or ROS camera_info YAML")
      .def_readonly("fx", &client::Camera::fx)
      .def_readonly("fy", &client::Camera::fy)
      .def_readonly("cx", &client::Camera::cx)
      .def_readonly("cy", &client::Camera::cy)
      .def_readonly("width", &client::Camera::width_px)
      .def_readonly("height", &client::Camera::height_px)
      .def_property_readonly("distortion", [](const client::Camera& c) {
        return Eigen::Matrix<double, 5, 1>(c.k1, c.k2, c.p1, c.p2, c.k3);
      }, "(5,) k1 k2 p1 p2 k3")
      .def("project", [](const client::Camera& c, const Eigen::Matrix<double, Eigen::Dynamic, 3>& points) {
        Eigen::Matrix<double, Eigen::Dynamic, 2> pixels(points.rows(), 2);
        for (Eigen::Index i = 0; i < points.rows(); ++i)
          pixels.row(i) = points(i, 2) > 0 ? c.project(points.row(i).transpose()).transpose()
                                           : Eigen::RowVector2d(kNaN, kNaN);
        return pixels;
      }, py::arg("points"), "(N, 2) pixels of (N, 3) points in the camera frame; NaN for z <= 0");

  py::class_<TransformGraph, std::shared_ptr<TransformGraph>>(
      m, "TransformGraph",
      "A tree of frames joined by uncertain transforms T_parent_child: static, or tracked by a stream. "
      "query(a, b) gives T_a_b with its BODY covariance, propagated through the lowest common ancestor.")
      .def(py::init([](const std::string& propagation) { return std::make_shared<TransformGraph>(propagation_of(propagation)); }),
           py::arg("propagation") = "lca", "'lca' (exact), or osgAR's 'osgar-root' / 'osgar-matrix16' (docs/background.md) for comparison")
      .def("add_static", [](TransformGraph& g, const std::string& parent, const std::string& child,
                            const Eigen::Matrix4d& T, const Mat6& covariance) {
             check(g.add_static_edge(parent, child, rigid(T), covariance));
           }, py::arg("parent"), py::arg("child"), py::arg("matrix"), py::arg("covariance") = Mat6::Zero().eval(),
           "A fixed (surveyed) edge: 4x4 T_parent_child and its 6x6 BODY covariance")
      .def("add_tracked", [](TransformGraph& g, const std::string& parent, const std::string& child,
                             const std::string& device, const std::string& sensor, double max_speed_mps,
                             double max_angular_speed_radps) {
             check(g.add_tracked_edge(parent, child, {device, sensor}, {max_speed_mps, max_angular_speed_radps}));
           }, py::arg("parent"), py::arg("child"), py::arg("device"), py::arg("sensor"),
           py::arg("max_speed_mps") = 0.0, py::arg("max_angular_speed_radps") = 0.0,
           "An edge bound to the stream device/sensor; its covariance grows with a report's age at "
           "these speeds. LOST until a report arrives.")
      .def("update", [](TransformGraph& g, const client::TrackedTransform& pose) { check(g.update(pose.stream, pose)); },
           py::arg("pose"), "Stores a Pose for the edges bound to its stream (ValueError if none is)")
      .def("query", [](const TransformGraph& g, const std::string& a, const std::string& b,
                       std::optional<std::int64_t> time_us) {
             return value_or_raise(g.query(a, b, time_us.value_or(now_us())));
           }, py::arg("a"), py::arg("b"), py::arg("time_us") = py::none(),
           "T_a_b at time_us (default: now, for the growth of stale tracked edges)")
      .def("has_frame", &TransformGraph::has_frame, py::arg("frame"));

  py::class_<ObjectResult>(m, "ObjectRegions",
                           "An object's registration error on the screen: each 3-D hull vertex's pixel and "
                           "2x2 covariance, and the outer and inner regions (counter-clockwise polygons, px)")
      .def_readonly("name", &ObjectResult::name)
      .def_readonly("frame", &ObjectResult::frame)
      .def_property_readonly("valid", [](const ObjectResult& o) { return o.regions.valid; },
                             "every vertex has a pixel and a bounded error: only then do the regions mean anything")
      .def_property_readonly("assessment_px", [](const ObjectResult& o) { return o.regions.assessment; },
                             "the largest semi-axis of the vertices' confidence ellipses; inf when not valid")
      .def_property_readonly("flags", [](const ObjectResult& o) { return cli::flag_names(o.regions.flags); })
      .def_property_readonly("vertices_m", [](const ObjectResult& o) {
        Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> v(o.hull_vertices_m.size(), 3);
        for (std::size_t i = 0; i < o.hull_vertices_m.size(); ++i) v.row(i) = o.hull_vertices_m[i].transpose();
        return v;
      }, "(N, 3) the object's 3-D hull vertices, in its frame")
      .def_property_readonly("mean_px", &vertex_means, "(N, 2) each vertex's mean pixel; NaN when it has none")
      .def_property_readonly("covariance_px2", &vertex_covariances, "(N, 2, 2); NaN when the vertex has none")
      .def_property_readonly("depth_m", [](const ObjectResult& o) {
        Eigen::VectorXd d(o.regions.vertices.size());
        for (std::size_t i = 0; i < o.regions.vertices.size(); ++i) d(i) = o.regions.vertices[i].depth_m;
        return d;
      }, "(N,) camera z of each vertex")
      .def_property_readonly("vertex_flags", [](const ObjectResult& o) {
        std::vector<std::vector<std::string>> out;
        for (const auto& v : o.regions.vertices) out.push_back(cli::flag_names(v.flags));
        return out;
      })
      .def_property_readonly("screen_hull", [](const ObjectResult& o) { return o.regions.hull; },
                             "indices of the vertices whose mean pixels form the hull, counter-clockwise")
      .def_property_readonly("outer_px", [](const ObjectResult& o) { return points_array(o.regions.outer); },
                             "(M, 2) holds every vertex with at least the confidence; empty when not valid")
      .def_property_readonly("inner_px", [](const ObjectResult& o) { return points_array(o.regions.inner); },
                             "(K, 2) surely covered by the object; empty when the error swamps it")
      .def("__repr__", [](const ObjectResult& o) {
        return "<covtrack.ObjectRegions " + o.name + (o.regions.valid ? " error " + std::to_string(o.regions.assessment) + " px>" : " NO REGION>");
      });

  m.def("object_regions",
        [](const client::Camera& camera, const Eigen::Matrix4d& T_camera_object, const Mat6& covariance,
           const std::vector<Vec3>& vertices, double confidence, const std::string& method) {
          if (!(confidence > 0 && confidence < 1)) throw py::value_error("confidence must be in (0, 1)");
          const UncertainPose T{rigid(T_camera_object), covariance, !covariance.allFinite()};
          return ObjectResult{"", "", vertices,
                              client::compute_object_regions(camera, T, vertices, region_options(confidence, method_of(method)))};
        },
        py::arg("camera"), py::arg("matrix"), py::arg("covariance"), py::arg("vertices"),
        py::arg("confidence") = 0.95, py::arg("method") = "unscented",
        "The regions of one object: the 4x4 T_camera_object with its 6x6 BODY covariance, and its "
        "vertices (N, 3) in its own frame, used as given (pass its 3-D hull)");

  py::class_<PyScene>(m, "Scene", "A scene file (config/scene_schema.md): frames, transforms, camera, objects")
      .def(py::init([](const std::string& path, std::optional<double> confidence) {
             return PyScene{value_or_raise(cli::load_regions_model(path, confidence.value_or(0)))};
           }), py::arg("path"), py::arg("confidence") = py::none(),
           "Loads it as `covtrack regions` does; ValueError naming file:line:column on a mistake")
      .def_property_readonly("path", [](const PyScene& s) { return s.model.scene_path; })
      .def_property_readonly("camera", [](const PyScene& s) { return s.model.camera; })
      .def_property_readonly("camera_frame", [](const PyScene& s) { return s.model.scene.camera.frame; })
      .def_property_readonly("confidence", [](const PyScene& s) { return s.model.confidence; })
      .def_property_readonly("objects", [](const PyScene& s) {
        std::vector<std::string> names;
        for (const auto& o : s.model.objects) names.push_back(o.name);
        return names;
      })
      .def_property_readonly("streams", [](const PyScene& s) {
        std::vector<std::pair<std::string, std::string>> out;
        for (const auto& t : s.model.scene.transforms)
          if (t.stream) out.emplace_back(t.stream->device, t.stream->sensor);
        return out;
      }, "(device, sensor) of each tracked transform")
      .def("graph", &PyScene::graph, py::arg("live") = false, py::arg("propagation") = "lca",
           py::arg("time_us") = py::none(),
           "The scene's TransformGraph. live=False: tracked edges report their scene values, "
           "measured at time_us (default now). live=True: they stay LOST until fed "
           "(Subscriber.feed(graph) or graph.update(pose)).")
      .def("regions", &PyScene::regions, py::arg("graph") = py::none(), py::arg("time_us") = py::none(),
           py::arg("method") = "unscented", py::arg("propagation") = "lca",
           "Every object's ObjectRegions at time_us (default now), from `graph`, or without one "
           "from the scene's own values as `covtrack regions SCENE` computes them");
}

}  // namespace covtrack::python
