#pragma once
// The parts of the `covtrack` Python module, each bound in its own file.
#include <string>

#include <pybind11/pybind11.h>

#include "covtrack/protocol/result.hpp"

namespace covtrack::python {

namespace py = pybind11;

void bind_pose(py::module_& m);        // Pose, Status
void bind_subscriber(py::module_& m);  // Subscriber, Stream, Device
void bind_scene(py::module_& m);       // Camera, TransformGraph, Scene, ObjectRegions
void bind_log(py::module_& m);         // read_log, Log, PoseStream, TruthStream

// Raises the Python exception `type` (e.g. PyExc_OSError) with `message`.
[[noreturn]] inline void raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw py::error_already_set();
}

// The value of a Result, or the Python exception E with the error's message.
template <typename E = py::value_error, typename T>
T value_or_raise(Result<T> result) {
  if (!result) throw E(result.error().message);
  return std::move(*result);
}
template <typename E = py::value_error>
void check(const Result<void>& result) {
  if (!result) throw E(result.error().message);
}

}  // namespace covtrack::python
