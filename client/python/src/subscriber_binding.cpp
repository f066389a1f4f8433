// covtrack.Subscriber over client::Subscriber: callbacks, a latest-value poll, waiting for
// the next report, stream counters, device states and rejections.
//
// Threads and the GIL: the C++ Subscriber receives on its own dispatch thread without the
// GIL. A Python callback is called on that thread with the GIL taken for the call.
// Waiting (wait_for) and stopping release the GIL, so the dispatch thread can run a
// callback meanwhile; a wait wakes every 50 ms to let Ctrl-C (KeyboardInterrupt) through.
// Subscribers still open when the interpreter exits are closed by an atexit hook, before
// Python tears down what a late callback would need.
#include <condition_variable>
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "covtrack/client/subscriber.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/protocol/channel_pattern.hpp"

namespace covtrack::python {
namespace {

using client::Subscriber;
using client::TrackedTransform;

// How often a wait gives Python a chance to raise KeyboardInterrupt.
constexpr auto kSignalCheck = std::chrono::milliseconds(50);

// Counts accepted reports per stream, so that a waiter can tell a new one from the last.
class Arrivals {
 public:
  void note(const std::string& key) {
    {
      std::lock_guard lock(mutex_);
      ++count_[key];
    }
    changed_.notify_all();
  }
  std::int64_t count(const std::string& key) const {
    std::lock_guard lock(mutex_);
    auto it = count_.find(key);
    return it == count_.end() ? 0 : it->second;
  }
  // True when the stream's count passed `seen` before `slice` ran out.
  bool wait_beyond(const std::string& key, std::int64_t seen, std::chrono::milliseconds slice) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, slice, [&] {
      auto it = count_.find(key);
      return it != count_.end() && it->second > seen;
    });
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, std::int64_t> count_;
};

// A Python callable kept by a C++ callback: released with the GIL held, whatever thread
// drops the last reference.
using SharedCallable = std::shared_ptr<py::object>;
SharedCallable share(py::object callable) {
  return SharedCallable(new py::object(std::move(callable)), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
}

// Set while this thread runs a Python callback: a callback must not close its subscriber
// (that would join the thread running it).
thread_local bool in_callback = false;

class PySubscriber;
std::mutex open_mutex;
std::set<PySubscriber*> open_subscribers;  // closed at interpreter exit

class PySubscriber {
 public:
  PySubscriber(const std::optional<std::string>& lcm_url, const std::string& streams, double stale_after_s,
               const std::optional<std::string>& key_file) {
    if (auto pattern = compile_channel_pattern(streams); !pattern)
      throw py::value_error("streams: " + pattern.error().message);
    if (!(stale_after_s > 0)) throw py::value_error("stale_after_s must be positive");
    client::SubscriberOptions options;
    options.lcm_url = lcm_url.value_or("");
    options.pattern = streams;
    options.stale_after_s = stale_after_s;
    options.key_file = key_file.value_or("");
    sub_ = value_or_raise<std::runtime_error>(Subscriber::open(options));
    (void)sub_->on_pose(".*", [arrivals = arrivals_](const TrackedTransform& t) { arrivals->note(t.stream.key()); });
    std::lock_guard lock(open_mutex);
    open_subscribers.insert(this);
  }
  // Never from its own callback (see close()).
  ~PySubscriber() { close(); }
  PySubscriber(const PySubscriber&) = delete;
  PySubscriber& operator=(const PySubscriber&) = delete;

  void on_pose(py::object callback, const std::string& pattern) {
    if (!PyCallable_Check(callback.ptr())) throw py::type_error("on_pose: callback must be callable");
    auto fn = share(std::move(callback));
    auto errors = callback_errors_;
    check(open().on_pose(pattern, [fn, errors](const TrackedTransform& t) {
      py::gil_scoped_acquire gil;
      in_callback = true;
      try {
        (*fn)(t);
      } catch (py::error_already_set& e) {
        ++*errors;
        e.discard_as_unraisable("covtrack.Subscriber pose callback");  // printed, like a thread's error
      } catch (const std::exception& e) {
        ++*errors;
        PyErr_SetString(PyExc_RuntimeError, e.what());
        PyErr_WriteUnraisable(nullptr);
      }
      in_callback = false;
    }));
  }

  // Every accepted report of a matching stream updates the graph, on the dispatch thread
  // without Python. Streams the graph has no edge for are left out.
  void feed(std::shared_ptr<client::TransformGraph> graph, const std::string& pattern) {
    if (!graph) throw py::type_error("feed: a TransformGraph is required");
    check(open().on_pose(pattern, [graph](const TrackedTransform& t) { (void)graph->update(t.stream, t); }));
  }

  std::optional<TrackedTransform> latest(const std::string& device, const std::string& sensor) const {
    return open().latest({device, sensor});
  }

  // The stream's next accepted report (or its first), or None after timeout_s.
  std::optional<TrackedTransform> wait_for(const std::string& device, const std::string& sensor,
                                           std::optional<double> timeout_s) {
    open();  // raises when closed
    if (timeout_s && !(*timeout_s >= 0 && *timeout_s < 1e9))  // also refuses NaN
      throw py::value_error("timeout_s must be from 0 to 1e9 s, or None");
    const StreamId id{device, sensor};
    const std::string key = id.key();
    const std::int64_t seen = arrivals_->count(key);
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(timeout_s.value_or(1e9)));
    auto arrivals = arrivals_;  // outlives a close() from another thread while we wait
    while (true) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      bool arrived = false;
      {
        py::gil_scoped_release release;
        arrived = arrivals->wait_beyond(key, seen, std::min(left, std::chrono::milliseconds(kSignalCheck)));
      }
      if (arrived) return open().latest(id);
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  std::vector<client::StreamState> streams() const { return open().streams(); }
  std::map<std::string, client::DeviceState> devices() const { return open().devices(); }
  std::map<std::string, std::int64_t> rejections() const { return open().rejections().by_reason; }
  std::optional<std::map<std::string, std::int64_t>> authentication() const {
    const auto a = open().authentication();
    if (!a) return std::nullopt;
    return std::map<std::string, std::int64_t>{{"authenticated", a->authenticated},
                                                {"unauthenticated", a->unauthenticated},
                                                {"forged", a->forged},
                                                {"replayed", a->replayed}};
  }
  std::int64_t callback_errors() const { return *callback_errors_; }
  bool closed() const { return !sub_; }

  // Stops receiving; the GIL is released meanwhile so a running callback can finish.
  void close() {
    if (!sub_) return;
    if (in_callback) throw std::runtime_error("a Subscriber cannot be closed from its own callback");
    if (PyGILState_Check()) {
      py::gil_scoped_release release;
      sub_->stop();
    } else {
      sub_->stop();
    }
    sub_.reset();  // drops the callbacks, which take the GIL: held here when it was on entry
    std::lock_guard lock(open_mutex);
    open_subscribers.erase(this);
  }

  static void close_all() {
    std::set<PySubscriber*> all;
    {
      std::lock_guard lock(open_mutex);
      all = open_subscribers;
    }
    for (PySubscriber* s : all) s->close();
  }

 private:
  Subscriber& open() const {
    if (!sub_) throw std::runtime_error("the Subscriber is closed");
    return *sub_;
  }

  std::unique_ptr<Subscriber> sub_;
  std::shared_ptr<Arrivals> arrivals_ = std::make_shared<Arrivals>();
  std::shared_ptr<std::atomic<std::int64_t>> callback_errors_ = std::make_shared<std::atomic<std::int64_t>>(0);
};

const char* state_name(std::int8_t state) {
  switch (state) {
    case device_status_t::STATE_STARTING: return "STARTING";
    case device_status_t::STATE_RUNNING: return "RUNNING";
    case device_status_t::STATE_FAILED: return "FAILED";
    case device_status_t::STATE_STOPPED: return "STOPPED";
  }
  return "UNKNOWN";
}

}  // namespace

void bind_subscriber(py::module_& m) {
  using client::DeviceState;
  using client::StreamState;
  py::class_<StreamState>(m, "Stream", "One stream as the subscriber has seen it: its last report and counters")
      .def_property_readonly("device", [](const StreamState& s) { return s.id.device; })
      .def_property_readonly("sensor", [](const StreamState& s) { return s.id.sensor; })
      .def_readonly("latest", &StreamState::latest, "the last accepted Pose, or None")
      .def_readonly("stale", &StreamState::stale, "no accepted report for stale_after_s")
      .def_property_readonly("received", [](const StreamState& s) { return s.counters.received; })
      .def_property_readonly("lost", [](const StreamState& s) { return s.counters.lost; },
                             "messages missing from the sequence")
      .def_property_readonly("rejected", [](const StreamState& s) { return s.counters.rejected; },
                             "malformed or invalid messages, never delivered")
      .def_property_readonly("foreign", [](const StreamState& s) { return s.counters.foreign; },
                             "valid messages off the stream's sequence (duplicates, a second publisher)")
      .def_property_readonly("restarts", [](const StreamState& s) { return s.counters.restarts; })
      .def_readonly("last_rejection", &StreamState::last_rejection)
      .def("__repr__", [](const StreamState& s) {
        return "<covtrack.Stream " + s.id.key() + " received=" + std::to_string(s.counters.received) + ">";
      });

  py::class_<DeviceState>(m, "Device", "A device as its heartbeats tell it (covtrack/status/<device>)")
      .def_property_readonly("name", [](const DeviceState& d) { return d.status.device; })
      .def_readonly("reachable", &DeviceState::reachable,
                    "a heartbeat within the last 3 periods; when not, its streams are reported LOST")
      .def_readonly("publishers", &DeviceState::publishers, "2 or more: several daemons publish it")
      .def_property_readonly(
          "publishing",
          [](const DeviceState& d) {
            std::vector<std::string> names;
            for (const auto& p : d.publishing) names.push_back(p.name());
            return names;
          },
          "\"host/pid\" of each daemon that publishes it, the newest last")
      .def_property_readonly(
          "second_publisher_warning",
          [](const DeviceState& d) { return covtrack::client::second_publisher_warning(d.status.device, d); },
          "\"device X published by two daemons: host/pid and host/pid\", or empty")
      .def_readonly("restarts", &DeviceState::restarts, "daemon restarts seen")
      .def_readonly("last_heard_us", &DeviceState::last_heard_us)
      .def_property_readonly("state", [](const DeviceState& d) { return state_name(d.status.state); },
                             "STARTING, RUNNING, FAILED or STOPPED")
      .def_property_readonly("driver", [](const DeviceState& d) { return d.status.driver; })
      .def_property_readonly("rate_hz", [](const DeviceState& d) { return d.status.rate_hz; })
      .def_property_readonly("reports", [](const DeviceState& d) { return d.status.reports; })
      .def_property_readonly("errors", [](const DeviceState& d) { return d.status.errors; })
      .def_property_readonly("last_error", [](const DeviceState& d) { return d.status.last_error; })
      .def_property_readonly("detail", [](const DeviceState& d) { return d.status.detail; })
      .def_property_readonly("host", [](const DeviceState& d) { return d.status.host; })
      .def_property_readonly("pid", [](const DeviceState& d) { return d.status.pid; })
      .def("__repr__", [](const DeviceState& d) {
        return "<covtrack.Device " + d.status.device + " " + state_name(d.status.state) +
               (d.reachable ? "" : " UNREACHABLE") + ">";
      });

  py::class_<PySubscriber>(m, "Subscriber",
                           "Receives covtrack pose streams and heartbeats over LCM on a thread of its own.")
      .def(py::init<const std::optional<std::string>&, const std::string&, double, const std::optional<std::string>&>(),
           py::arg("lcm_url") = py::none(), py::arg("streams") = ".*", py::arg("stale_after_s") = 0.5,
           py::arg("key_file") = py::none(),
           "lcm_url: None for $LCM_DEFAULT_URL or LCM's default. streams: a POSIX extended regular "
           "expression that must match 'device/sensor' whole. key_file: the daemon's shared key "
           "(its [auth] key_file; None: $COVTRACK_KEY_FILE, if set): only authenticated messages are "
           "accepted. Raises RuntimeError when LCM cannot be used (e.g. no multicast route: the "
           "message says how to add one) or the key file cannot.")
      .def("on_pose", &PySubscriber::on_pose, py::arg("callback"), py::arg("pattern") = ".*",
           "Calls callback(pose) for every accepted report of the streams whose 'device/sensor' "
           "matches pattern, on the receiving thread with the GIL held: keep it short. An exception "
           "it raises is printed and counted (callback_errors), and receiving goes on.")
      .def("feed", &PySubscriber::feed, py::arg("graph"), py::arg("pattern") = ".*",
           "Keeps a TransformGraph up to date: every accepted report of a matching stream updates "
           "it on the receiving thread, without Python or the GIL.")
      .def("latest", &PySubscriber::latest, py::arg("device"), py::arg("sensor"),
           "The stream's last accepted Pose, or None if none arrived yet.")
      .def("wait_for", &PySubscriber::wait_for, py::arg("device"), py::arg("sensor"),
           py::arg("timeout_s") = py::none(),
           "Waits (without the GIL) for the stream's next accepted Pose and returns it, or None "
           "after timeout_s seconds (None: no limit).")
      .def("streams", &PySubscriber::streams, "Every stream seen so far (list of Stream), by name")
      .def("devices", &PySubscriber::devices, "Every device heard so far: {name: Device}")
      .def("rejections", &PySubscriber::rejections,
           "Messages rejected so far, by reason: {'bad length': 2, 'invalid pose': 1, ...}")
      .def("authentication", &PySubscriber::authentication,
           "With a key: {'authenticated': n, 'unauthenticated': n, 'forged': n, 'replayed': n}; else None")
      .def_property_readonly("callback_errors", &PySubscriber::callback_errors)
      .def_property_readonly("closed", &PySubscriber::closed)
      .def("close", &PySubscriber::close, "Stops receiving (idempotent); no callback runs after it.")
      .def("__enter__", [](PySubscriber& s) -> PySubscriber& { return s; }, py::return_value_policy::reference)
      .def("__exit__", [](PySubscriber& s, py::args) { s.close(); });

  // Before the interpreter finalises: a dispatch thread must not wait for the GIL then.
  py::module_::import("atexit").attr("register")(py::cpp_function(&PySubscriber::close_all));
}

}  // namespace covtrack::python
