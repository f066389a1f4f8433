// The `covtrack` Python module: covtrack streams, transform graphs, screen error regions
// and logs as NumPy arrays (client/python/README.md).
#include "bindings.hpp"

PYBIND11_MODULE(_covtrack, m) {
  m.doc() = "covtrack: tracked poses with honest 6x6 covariances, from LCM or logs, and the "
            "screen error regions they cause (client/python/README.md)";
  m.attr("__version__") = COVTRACK_VERSION;
  covtrack::python::bind_pose(m);
  covtrack::python::bind_subscriber(m);
  covtrack::python::bind_scene(m);
  covtrack::python::bind_log(m);
}
