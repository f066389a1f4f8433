// covtrack.Pose: one accepted report of a stream (client::TrackedTransform), its values as
// fresh NumPy arrays; covtrack.Status.
#include <fmt/format.h>
#include <pybind11/eigen.h>

#include "bindings.hpp"
#include "covtrack/client/tracked_transform.hpp"
#include "log_columns.hpp"

namespace covtrack::python {

void bind_pose(py::module_& m) {
  py::enum_<TrackingStatus>(m, "Status", "A report's tracking status (protocol/README.md)")
      .value("OK", TrackingStatus::Ok, "the device measures the sensor")
      .value("DEGRADED", TrackingStatus::Degraded, "reporting from a weaker source; the covariance says how much")
      .value("LOST", TrackingStatus::Lost, "no information: pose and covariance must not be used");

  using client::TrackedTransform;
  py::class_<TrackedTransform>(m, "Pose",
                               "One report of a stream: the pose T_parent_child (maps child coordinates into "
                               "the parent frame) with its 6x6 covariance in the BODY convention "
                               "T_true = T * Exp(xi), xi = [translation, rotation] (m, rad).")
      .def(py::init([](const std::string& device, const std::string& sensor, const std::string& parent_frame,
                       const std::string& child_frame, const Vec3& position, const Eigen::Vector4d& quaternion_wxyz,
                       const Mat6& covariance, TrackingStatus status, std::int64_t time_us) {
             if (!position.allFinite() || !quaternion_wxyz.allFinite() || quaternion_wxyz.norm() < 1e-12)
               throw py::value_error("Pose: position and quaternion must be finite, the quaternion non-zero");
             TrackedTransform t;
             t.stream = {device, sensor};
             t.parent_frame = parent_frame;
             t.child_frame = child_frame;
             const Eigen::Vector4d& q = quaternion_wxyz;
             t.T_parent_child = pose_from(position, Eigen::Quaterniond(q[0], q[1], q[2], q[3]));
             t.covariance = covariance;
             t.status = status;
             t.measurement_time_us = t.publish_time_us = t.receive_time_us = time_us;
             return t;
           }),
           py::arg("device"), py::arg("sensor"), py::arg("parent_frame"), py::arg("child_frame"),
           py::arg("position"), py::arg("quaternion"), py::arg("covariance") = Mat6::Zero().eval(),
           py::arg("status") = TrackingStatus::Ok, py::arg("time_us") = 0,
           "A report made by hand (e.g. to feed a TransformGraph); the quaternion is w, x, y, z "
           "and is normalised")
      .def_property_readonly("device", [](const TrackedTransform& t) { return t.stream.device; })
      .def_property_readonly("sensor", [](const TrackedTransform& t) { return t.stream.sensor; })
      .def_readonly("parent_frame", &TrackedTransform::parent_frame)
      .def_readonly("child_frame", &TrackedTransform::child_frame)
      .def_property_readonly(
          "position", [](const TrackedTransform& t) { return Vec3(t.T_parent_child.translation()); },
          "(3,) the child origin in the parent frame, metres")
      .def_property_readonly(
          "quaternion", [](const TrackedTransform& t) { return quaternion_wxyz(t.T_parent_child); },
          "(4,) the rotation as a unit quaternion w, x, y, z with w >= 0")
      .def_property_readonly(
          "matrix", [](const TrackedTransform& t) { return Eigen::Matrix4d(t.T_parent_child.matrix()); },
          "(4, 4) the homogeneous transform T_parent_child")
      .def_property_readonly(
          "covariance", [](const TrackedTransform& t) { return Mat6(t.covariance); },
          "(6, 6) BODY covariance, [tx ty tz rx ry rz]; +inf on the diagonal when LOST")
      .def_readonly("status", &TrackedTransform::status)
      .def_property_readonly("lost", &TrackedTransform::lost, "status is LOST: do not use pose or covariance")
      .def_readonly("time_us", &TrackedTransform::measurement_time_us,
                    "when the device measured it, microseconds since the Unix epoch (CLOCK_REALTIME)")
      .def_readonly("publish_time_us", &TrackedTransform::publish_time_us)
      .def_readonly("receive_time_us", &TrackedTransform::receive_time_us)
      .def_readonly("sequence", &TrackedTransform::sequence)
      .def_readonly("device_unreachable", &TrackedTransform::device_unreachable,
                    "reported LOST by this client because the device's heartbeats stopped")
      .def("__repr__", [](const TrackedTransform& t) {
        const Vec3 p = t.T_parent_child.translation();
        return fmt::format("<covtrack.Pose {} {} -> {} {} position=[{:.4f}, {:.4f}, {:.4f}] time_us={}>",
                           t.stream.key(), t.parent_frame, t.child_frame, to_string(t.status), p.x(), p.y(),
                           p.z(), t.measurement_time_us);
      });
}

}  // namespace covtrack::python
