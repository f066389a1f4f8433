// covtrack.read_log(): an LCM log's pose and truth streams as NumPy arrays, read through
// the checks of log_columns.hpp, so that a damaged or hostile log is counted, never a crash.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "log_columns.hpp"

namespace covtrack::python {
namespace {

// The vector's values as an array of `shape`, without a copy: the array owns the vector.
template <typename T>
py::array_t<T> to_array(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free_it(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), free_it);
}

// A stream's columns as Python sees them: names, and arrays with one row per message.
struct PyStream {
  std::string device, sensor, parent_frame, child_frame;
  py::ssize_t rows = 0;
  py::dict arrays;  // name -> array
};

PyStream truth_stream(TruthColumns&& c) {
  const auto n = static_cast<py::ssize_t>(c.size());
  PyStream s{c.id.device, c.id.sensor, c.parent_frame, c.child_frame, n, {}};
  s.arrays["log_time_us"] = to_array(std::move(c.log_time_us), {n});
  s.arrays["time_us"] = to_array(std::move(c.measurement_time_us), {n});
  s.arrays["sequence"] = to_array(std::move(c.sequence), {n});
  s.arrays["position"] = to_array(std::move(c.position_m), {n, 3});
  s.arrays["quaternion"] = to_array(std::move(c.quaternion_wxyz), {n, 4});
  return s;
}

PyStream pose_stream(PoseColumns&& c) {
  const auto n = static_cast<py::ssize_t>(c.size());
  auto publish = std::move(c.publish_time_us);
  auto covariance = std::move(c.covariance);
  auto status = std::move(c.status);
  PyStream s = truth_stream(std::move(c));
  s.arrays["publish_time_us"] = to_array(std::move(publish), {n});
  s.arrays["covariance"] = to_array(std::move(covariance), {n, 6, 6});
  s.arrays["status"] = to_array(std::move(status), {n});
  return s;
}

struct PyLog {
  std::string path;
  std::map<std::string, PyStream> poses;
  std::map<std::string, PyStream> truth;
  std::int64_t events = 0;
  RejectionTally rejections;
  std::vector<lcmlog::LogDamage> damage;
};

PyLog read_log(const std::string& path) {
  Result<LogColumns> columns;
  {
    py::gil_scoped_release release;  // a long log reads without holding other threads up
    columns = read_log_columns(path);
  }
  if (!columns) raise(PyExc_OSError, columns.error().message);
  PyLog log{path, {}, {}, columns->events, std::move(columns->rejections), std::move(columns->damage)};
  for (auto& [key, c] : columns->poses) log.poses.emplace(key, pose_stream(std::move(c)));
  for (auto& [key, c] : columns->truth) log.truth.emplace(key, truth_stream(std::move(c)));
  return log;
}

// Arrays are attributes of a stream: stream.position, stream.covariance, ...
py::object stream_array(const PyStream& s, const std::string& name) {
  if (!s.arrays.contains(name)) throw py::attribute_error("no array '" + name + "' in this stream");
  return s.arrays[py::str(name)];
}

}  // namespace

void bind_log(py::module_& m) {
  py::class_<PyStream>(m, "LogStream",
                       "One stream of a log, one row per message in log order. Pose streams: time_us, "
                       "publish_time_us, log_time_us, sequence (N,), position (N, 3), quaternion (N, 4) "
                       "w x y z, covariance (N, 6, 6) BODY (+inf diagonal when LOST), status (N,) int8 "
                       "(Status values). Truth streams: the same without publish_time_us, covariance "
                       "and status.")
      .def_readonly("device", &PyStream::device)
      .def_readonly("sensor", &PyStream::sensor)
      .def_readonly("parent_frame", &PyStream::parent_frame, "of the stream's first message")
      .def_readonly("child_frame", &PyStream::child_frame)
      .def_property_readonly("arrays", [](const PyStream& s) { return s.arrays.attr("keys")(); })
      .def("__len__", [](const PyStream& s) { return s.rows; })
      .def("__getattr__", &stream_array)
      .def("__repr__", [](const PyStream& s) {
        return "<covtrack.LogStream " + s.device + "/" + s.sensor + " " + std::to_string(s.rows) + " rows>";
      });

  py::class_<lcmlog::LogDamage>(m, "LogDamage", "A byte range of the file that holds no good event")
      .def_readonly("offset", &lcmlog::LogDamage::offset)
      .def_readonly("skipped_bytes", &lcmlog::LogDamage::skipped_bytes)
      .def_readonly("truncated", &lcmlog::LogDamage::truncated, "it runs to the end of the file")
      .def("__repr__", [](const lcmlog::LogDamage& d) { return "<covtrack.LogDamage " + lcmlog::describe(d) + ">"; });

  py::class_<PyLog>(m, "Log", "An LCM log read by read_log()")
      .def_readonly("path", &PyLog::path)
      .def_readonly("poses", &PyLog::poses, "{'device/sensor': LogStream} of covtrack/pose/ channels")
      .def_readonly("truth", &PyLog::truth, "{'device/sensor': LogStream} of covtrack/truth/ channels")
      .def_readonly("events", &PyLog::events, "good events read, of every channel")
      .def_property_readonly("rejected", [](const PyLog& l) { return l.rejections.by_reason; },
                             "pose and truth messages left out, by reason: {'bad length': 1, ...}")
      .def_property_readonly("rejected_total", [](const PyLog& l) { return l.rejections.total; })
      .def_property_readonly("last_rejection", [](const PyLog& l) { return l.rejections.last; },
                             "channel and description of the last message left out")
      .def_readonly("damage", &PyLog::damage, "list of LogDamage: bytes skipped to resynchronise")
      .def("__repr__", [](const PyLog& l) {
        return "<covtrack.Log " + l.path + ": " + std::to_string(l.poses.size()) + " pose streams, " +
               std::to_string(l.rejections.total) + " rejected, " + std::to_string(l.damage.size()) + " damaged ranges>";
      });

  m.def("read_log", &read_log, py::arg("path"),
        "Reads an LCM log's covtrack pose and truth streams into NumPy arrays. Every message is "
        "checked as a live client checks it: damaged bytes are skipped and listed (Log.damage), "
        "malformed or invalid messages are left out and counted by reason (Log.rejected). Raises "
        "OSError when the file cannot be read.");
}

}  // namespace covtrack::python
