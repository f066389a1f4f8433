#pragma once
// An emulated serial 6-DOF tracker (FASTRAK / IS-900, LIBERTY / PATRIOT, Flock of Birds)
// behind a pseudo-terminal: it answers status, who-am-I and examine requests, honours
// the unit and output-list commands, takes its reset time, and streams records at the
// device's rate with noise drawn from the model's covariance (src/covariance_model.hpp),
// reporting each noise-free pose as truth.
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"

namespace covtrack::emulate6dof {

struct EmulatedStation {
  int number = 1;
  std::string name;  // the sensor name used for truth samples
  Pose T_source_receiver = Pose::Identity();  // where the receiver sits (static)
};

struct EmulatorConfig {
  serial6dof::Model model = serial6dof::Model::Fastrak;
  std::string link_path;        // stable path for the driver (a symbolic link); empty: none
  std::string parent_frame = "world";
  std::vector<EmulatedStation> stations;
  double rate_hz = 0;           // per station; 0: the model's
  double reset_time_s = -1;     // < 0: the model's
  std::uint64_t seed = 1;
  double trouble_every_s = 0;   // flag one record set this often (0: never); noise inflated
  double trouble_inflation = 10;  // must match the driver's to keep the covariance honest
  int flock_scale_code = 0;     // answer to examine position scaling: 0 = 36 in, 1 = 72 in
  // Motion: each receiver sways about its pose, every axis a sine of its own frequency
  // (sway_hz to 1.7 x sway_hz); 0 amplitudes: static receivers.
  double sway_m = 0;
  double sway_rad = 0;
  double sway_hz = 0.5;
  // Line noise on the streamed records (replies during configuration stay clean):
  // events per second, at random bytes.
  double bit_flips_per_s = 0;
  double bytes_dropped_per_s = 0;
  double bytes_duplicated_per_s = 0;
};

// Receivers spread in front of the source, each at its own attitude: a default layout.
std::vector<EmulatedStation> default_stations(const std::vector<int>& numbers);

class Emulator {
 public:
  using TruthCallback = std::function<void(const TruthSample&)>;

  // Creates the pseudo-terminal; the thread starts with start(). The unit streams,
  // resets and stamps its truth on `clock`'s time.
  static Result<std::unique_ptr<Emulator>> create(const EmulatorConfig& config, DriverClock& clock = real_clock());
  ~Emulator();

  void start(TruthCallback on_truth);
  void stop();

  const std::string& device_path() const { return device_path_; }
  // Like pulling and re-inserting the USB cable (handled on the emulator's thread).
  void unplug() { want_plugged_ = false; }
  void replug() { want_plugged_ = true; }
  bool plugged() const { return plugged_; }
  // A hung unit: it stops streaming but still listens; a reset cures it.
  void hang() { hung_ = true; }
  bool hung() const { return hung_; }

  std::uint64_t records_sent() const { return records_sent_; }
  // Line-noise events applied so far (flips, drops and duplications).
  std::uint64_t noise_events() const { return noise_events_; }
  std::uint64_t resets() const { return resets_; }
  bool resetting() const { return resetting_; }

 private:
  class Impl;
  explicit Emulator(std::unique_ptr<Impl> impl);

  std::unique_ptr<Impl> impl_;
  std::string device_path_;
  std::jthread thread_;
  std::atomic<bool> want_plugged_{true}, plugged_{true}, resetting_{false}, hung_{false};
  std::atomic<std::uint64_t> records_sent_{0}, resets_{0}, noise_events_{0};
};

}  // namespace covtrack::emulate6dof
