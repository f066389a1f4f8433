#pragma once
// Shared by the record/replay tests: temporary directories, varied covtrack messages,
// an LCM collector thread, and child processes with their stderr in a file.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/pose_cov_t.hpp"
#include "covtrack/raw_bytes_t.hpp"

extern char** environ;

namespace covtrack::testing {

struct Message {
  std::string channel;
  std::vector<std::byte> bytes;
  bool operator==(const Message&) const = default;
};

inline std::filesystem::path make_temp_dir() {
  std::string tmpl = (std::filesystem::temp_directory_path() / "covtrack-rec-XXXXXX").string();
  if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
  return tmpl;
}

template <typename T>
std::vector<std::byte> encode(const T& msg) {
  std::vector<std::byte> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// Poses on three streams and raw bytes of varying length on a fourth channel, with
// random contents so that a swapped or altered payload cannot go unnoticed.
inline std::vector<Message> make_messages(std::size_t count, std::uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> real(-10, 10);
  const char* sensors[] = {"head", "wand", "camera"};
  std::vector<Message> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    if (i % 4 == 3) {
      covtrack::raw_bytes_t raw{};
      raw.time_us = static_cast<std::int64_t>(i) * 1000;
      raw.device = "fastrak";
      raw.direction = static_cast<std::int8_t>(i % 2);
      raw.length = static_cast<std::int32_t>(rng() % 200);
      for (int b = 0; b < raw.length; ++b) raw.data.push_back(static_cast<std::uint8_t>(rng()));
      out.push_back({"covtrack/raw/fastrak", encode(raw)});
      continue;
    }
    covtrack::pose_cov_t pose{};
    pose.measurement_time_us = static_cast<std::int64_t>(i) * 1000;
    pose.publish_time_us = pose.measurement_time_us + 250;
    pose.sequence = static_cast<std::int64_t>(i);
    pose.device = "sim";
    pose.sensor = sensors[i % 4];
    pose.parent_frame = "world";
    pose.child_frame = pose.sensor;
    for (double& v : pose.position_m) v = real(rng);
    for (double& v : pose.orientation_wxyz) v = real(rng);
    for (double& v : pose.covariance) v = real(rng);
    pose.status = static_cast<std::int8_t>(i % 3);
    out.push_back({"covtrack/pose/sim/" + pose.sensor, encode(pose)});
  }
  return out;
}

// Subscribes to everything on `url` and keeps what arrives, in order, from its own thread.
class Collector {
 public:
  explicit Collector(const std::string& url) : lcm_(url) {
    if (!lcm_.good()) throw std::runtime_error("LCM failed to open " + url);
    auto* sub = lcm_.subscribe(".*", &Collector::on_message, this);
    sub->setQueueCapacity(1 << 20);
    thread_ = std::thread([this] {
      while (!done_) lcm_.handleTimeout(20);
    });
  }
  ~Collector() {
    done_ = true;
    thread_.join();
  }
  // Waits for a condition, not a fixed time: returns as soon as `count` messages are in.
  bool wait_for(std::size_t count, std::chrono::seconds timeout = std::chrono::seconds(20)) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return messages_.size() >= count; });
  }
  std::vector<Message> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(messages_, {});
  }
  std::size_t size() {
    std::lock_guard lock(mutex_);
    return messages_.size();
  }

 private:
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (channel == "LCM_SELF_TEST") return;  // other LCM instances probing their loopback
    const auto* data = static_cast<const std::byte*>(rbuf->data);
    std::lock_guard lock(mutex_);
    messages_.push_back({channel, std::vector<std::byte>(data, data + rbuf->data_size)});
    cv_.notify_all();
  }

  lcm::LCM lcm_;
  std::atomic<bool> done_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Message> messages_;
  std::thread thread_;
};

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Polls `done` until it holds or the timeout passes (for conditions in other processes).
inline bool eventually(const std::function<bool()>& done,
                       std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

// Good events in a log (0 if it cannot be opened).
inline std::size_t count_events(const std::filesystem::path& path) {
  auto reader = covtrack::lcmlog::LogReader::open(path.string());
  if (!reader) return 0;
  std::size_t n = 0;
  while (reader->next()) ++n;
  return n;
}

inline std::vector<Message> read_log(const std::filesystem::path& path) {
  auto reader = covtrack::lcmlog::LogReader::open(path.string());
  std::vector<Message> out;
  if (!reader) return out;
  while (auto e = reader->next())
    out.push_back({std::string(e->channel), {e->payload.begin(), e->payload.end()}});
  return out;
}

// A child process; stdout and stderr go to a file the test can read while it runs.
class Child {
 public:
  Child(std::vector<std::string> argv, const std::filesystem::path& output) : output_(output) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, output.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + argv[0]);
  }
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }
  void signal(int sig) { ::kill(pid_, sig); }
  // Exit code, or 128 + signal number.
  int wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  std::string output() const { return read_file(output_); }

 private:
  pid_t pid_ = -1;
  std::filesystem::path output_;
};

// Runs a command to completion; returns its exit code and output.
inline std::pair<int, std::string> run(std::vector<std::string> argv,
                                       const std::filesystem::path& output) {
  Child child(std::move(argv), output);
  const int code = child.wait();
  return {code, read_file(output)};
}

}  // namespace covtrack::testing
