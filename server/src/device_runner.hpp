#pragma once
// One device on its own thread: runs its driver, and when the driver fails records why
// and restarts it after a growing back-off, while every other device keeps running.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include <covtrack/device_status_t.hpp>

#include "config.hpp"
#include "publisher.hpp"

namespace covtrack::server {

class DeviceRunner {
 public:
  DeviceRunner(DeviceConfig device, Publisher& publisher, const DaemonSettings& settings);
  ~DeviceRunner();  // stops and joins

  void start();
  void request_stop();
  // Another daemon publishes this device: stop the driver and send no more heartbeats.
  void release();
  bool released() const { return released_; }
  // Waits for the thread until `deadline`; false if it is still running then (its
  // driver is blocked in a call that ignores the stop request). A true join never blocks.
  bool join_until(std::chrono::steady_clock::time_point deadline);
  void join();

  // The heartbeat: counters since start, rate since the previous call.
  device_status_t heartbeat();
  const std::string& name() const { return device_.name; }
  const std::string& type() const { return device_.type; }

 private:
  class Sink;
  void supervise(std::stop_token stop);
  void record_failure(const std::string& message);

  DeviceConfig device_;
  Publisher& publisher_;
  DaemonSettings settings_;

  std::atomic<std::int8_t> state_{device_status_t::STATE_STARTING};
  std::atomic<bool> released_{false};
  std::atomic<std::int64_t> reports_{0}, errors_{0}, resyncs_{0}, drops_{0}, restarts_{0};
  std::mutex text_mutex_;  // guards the two texts below
  std::string last_error_;
  std::string detail_;  // SampleSink::running's, cleared when the driver fails

  std::int64_t reports_at_last_heartbeat_ = 0;
  std::chrono::steady_clock::time_point last_heartbeat_ = std::chrono::steady_clock::now();

  std::mutex finished_mutex_;
  std::condition_variable finished_cv_;
  bool finished_ = false;  // supervise() has returned: joining cannot block

  std::jthread thread_;
};

}  // namespace covtrack::server
