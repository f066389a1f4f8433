#pragma once
// An emulated Lenz Digital Plus set behind an LI101F or LI-USB, on a pseudo-terminal:
// a train runs the layout with a speed profile, the section under the locomotive's
// centre reads occupied, changes go out as feedback broadcasts (several pairs in one
// message when two modules or nibbles change at once), and the interface answers the
// version, status and feedback requests a driver sends. The true vehicle poses go to a
// callback (the truth channel, in `covtrack emulate-lenz`).
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stop_token>
#include <string>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/devices/serial/pseudo_terminal.hpp"
#include "covtrack/emulators/lenz/train_motion.hpp"
#include "track_layout.hpp"
#include "xpressnet_framing.hpp"
#include "xpressnet_messages.hpp"

namespace covtrack::lenz {

struct LenzEmulatorOptions {
  std::shared_ptr<const TrackLayout> layout;
  Interface interface = Interface::Li101f;
  std::vector<SpeedStep> profile;
  double accel_mps2 = 0;        // 0: 80% of the layout's max_accel_mps2
  double start_s = 0;           // where the locomotive's centre starts
  std::string link_path;        // stable path to the pseudo-terminal's slave ("": none)
  std::string parent_frame = "world";
  double truth_hz = 50;
  double tick_s = 0.002;        // how often occupancy is re-evaluated
};

class LenzEmulator {
 public:
  // The train moves, and occupancy is evaluated, on `clock`'s time.
  static Result<std::unique_ptr<LenzEmulator>> create(LenzEmulatorOptions options, DriverClock& clock = real_clock());

  // The path a driver's `port` should name.
  std::string device_path() const { return pty_.device_path(); }
  std::string slave_path() const { return pty_.slave_path(); }
  const TrainMotion& motion() const { return motion_; }
  const TrackLayout& layout() const { return *options_.layout; }
  // The clock's now_us() at the train's t = 0: the locomotive is at motion().s_at(now - start).
  std::int64_t start_time_us() const { return start_us_; }
  double true_s_at(std::int64_t time_us) const;

  // Runs until stop. `truth` may be empty.
  void run(std::stop_token stop, const std::function<void(const TruthSample&)>& truth);

  // Thread-safe: the running loop closes (unplug) or recreates (replug) the terminal.
  void unplug() { want_plugged_ = false; }
  void replug() { want_plugged_ = true; }
  // Thread-safe: sends a feedback broadcast that is not true, as line noise whose XOR
  // byte happens to check would (the running loop writes it).
  void forge_feedback(const FeedbackPair& pair);
  std::uint64_t requests_answered() const { return requests_answered_; }
  std::uint64_t broadcasts_sent() const { return broadcasts_sent_; }

 private:
  LenzEmulator(LenzEmulatorOptions options, serial::PseudoTerminal pty, DriverClock& clock);
  void answer(const Frame& frame);
  void send(const Reply& reply, Prefix prefix);
  void update_occupancy(double s);
  std::uint8_t nibble(int module, bool upper) const;
  void publish_truth(const std::function<void(const TruthSample&)>& truth, std::int64_t time_us, double s);

  LenzEmulatorOptions options_;
  DriverClock& clock_;
  serial::PseudoTerminal pty_;
  TrainMotion motion_;
  FrameDecoder decoder_;
  std::map<int, std::uint8_t> module_inputs_;  // RS-bus module -> inputs 1-8 (bit 0 = input 1)
  std::size_t occupied_section_ = 0;
  std::int64_t start_us_ = 0;
  std::atomic<bool> want_plugged_{true};
  std::atomic<std::uint64_t> requests_answered_{0}, broadcasts_sent_{0};
  bool track_power_ = true;
  std::mutex forged_mutex_;
  std::vector<FeedbackPair> forged_;
};

}  // namespace covtrack::lenz
