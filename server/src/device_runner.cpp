#include "device_runner.hpp"

#include <algorithm>
#include <exception>

#include <spdlog/spdlog.h>

#include "covtrack/devices/interruptible_sleep.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/wire_text.hpp"
#include "driver_factory.hpp"

namespace covtrack::server {
namespace {
// A driver that ran this long before failing starts again at the initial back-off.
constexpr auto kHealthyRun = std::chrono::seconds(30);
}  // namespace

// What the driver sees: publishing plus the counters of its heartbeat.
class DeviceRunner::Sink final : public SampleSink {
 public:
  explicit Sink(DeviceRunner& runner) : r_(runner) {}
  void pose(const PoseSample& s) override {
    r_.state_ = device_status_t::STATE_RUNNING;
    if (r_.publisher_.pose(r_.device_.name, s)) ++r_.reports_;
    else ++r_.drops_;
  }
  void truth(const TruthSample& s) override {
    if (!r_.publisher_.truth(r_.device_.name, s)) ++r_.drops_;
  }
  void raw(ByteDirection d, const std::uint8_t* data, std::size_t size) override {
    if (!r_.publisher_.raw(r_.device_.name, d, data, size)) ++r_.drops_;
  }
  void image(const ImageSample& s) override {
    if (!r_.publisher_.image(r_.device_.name, s)) ++r_.drops_;
  }
  void count_error(const std::string& what) override {
    ++r_.errors_;
    std::lock_guard lock(r_.text_mutex_);
    r_.last_error_ = what;
  }
  void running(const std::string& detail) override {
    r_.state_ = device_status_t::STATE_RUNNING;
    std::lock_guard lock(r_.text_mutex_);
    r_.detail_ = detail;
  }
  void count_resync() override { ++r_.resyncs_; }
  void count_drop() override { ++r_.drops_; }

 private:
  DeviceRunner& r_;
};

DeviceRunner::DeviceRunner(DeviceConfig device, Publisher& publisher, const DaemonSettings& settings)
    : device_(std::move(device)), publisher_(publisher), settings_(settings) {}

DeviceRunner::~DeviceRunner() {
  request_stop();
  join();
}

void DeviceRunner::start() {
  thread_ = std::jthread([this](std::stop_token stop) {
    supervise(stop);
    std::lock_guard lock(finished_mutex_);
    finished_ = true;
    finished_cv_.notify_all();
  });
}

void DeviceRunner::request_stop() { thread_.request_stop(); }

void DeviceRunner::release() {
  released_ = true;
  request_stop();
}

bool DeviceRunner::join_until(std::chrono::steady_clock::time_point deadline) {
  if (!thread_.joinable()) return true;
  {
    std::unique_lock lock(finished_mutex_);
    if (!finished_cv_.wait_until(lock, deadline, [this] { return finished_; })) return false;
  }
  thread_.join();
  return true;
}

void DeviceRunner::join() {
  if (thread_.joinable()) thread_.join();
}

void DeviceRunner::record_failure(const std::string& message) {
  ++errors_;
  state_ = device_status_t::STATE_FAILED;
  std::lock_guard lock(text_mutex_);
  last_error_ = message;
  detail_.clear();  // it described the run that failed
}

void DeviceRunner::supervise(std::stop_token stop) {
  using namespace std::chrono;
  Sink sink(*this);
  duration<double> backoff(settings_.restart_backoff_initial_s);
  const duration<double> backoff_max(settings_.restart_backoff_max_s);

  for (std::uint64_t run = 0; !stop.stop_requested(); ++run) {
    const auto started = steady_clock::now();
    Result<void> result;
    try {  // an exception must not cross the thread boundary: it becomes a failure
      auto driver = make_driver(device_.options, run);
      result = driver->run(sink, stop);
    } catch (const std::exception& e) {
      result = fail(std::string("driver threw: ") + e.what());
    }
    if (stop.stop_requested()) break;
    if (result) result = fail("driver stopped on its own");

    if (steady_clock::now() - started > kHealthyRun)
      backoff = duration<double>(settings_.restart_backoff_initial_s);
    record_failure(result.error().message);
    spdlog::error("device '{}' failed: {}; restarting in {:.2f} s", device_.name,
                  result.error().message, backoff.count());
    if (!sleep_for(stop, backoff)) break;
    backoff = std::min(backoff * 2, backoff_max);
    ++restarts_;
    state_ = device_status_t::STATE_STARTING;
  }
  state_ = device_status_t::STATE_STOPPED;
}

device_status_t DeviceRunner::heartbeat() {
  const auto now = std::chrono::steady_clock::now();
  const double dt = std::chrono::duration<double>(now - last_heartbeat_).count();
  const std::int64_t reports = reports_;

  device_status_t s;
  s.time_us = now_us();
  s.device = device_.name;
  s.driver = device_.type;
  s.state = state_;
  s.rate_hz = dt > 0 ? static_cast<double>(reports - reports_at_last_heartbeat_) / dt : 0;
  s.reports = reports;
  s.errors = errors_;
  s.resyncs = resyncs_;
  s.drops = drops_;
  s.restarts = restarts_;
  {
    std::lock_guard lock(text_mutex_);
    // An error message may quote bytes a device sent; clients reject a heartbeat whose
    // text is not UTF-8 (protocol/README.md), so they go out escaped.
    s.last_error = printable(last_error_);
    s.detail = printable(detail_);
  }
  reports_at_last_heartbeat_ = reports;
  last_heartbeat_ = now;
  return s;
}

}  // namespace covtrack::server
