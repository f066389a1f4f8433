#include "covtrack/devices/hydra/hydra_driver.hpp"

#include <chrono>

#include <fmt/format.h>
#include <hidapi/hidapi.h>

#include "covtrack/devices/file_kind.hpp"
#include "covtrack/devices/valid_frame_watchdog.hpp"
#include "hydra_report.hpp"
#include "hydra_stream.hpp"

namespace covtrack::hydra {
namespace {

using Clock = DriverClock;
constexpr std::chrono::milliseconds kReadPoll(20);  // a stop is noticed within this
// VRPN's experience: a base may need the mode switch repeated; give it this long.
constexpr double kModeSwitchRetry_s = 2.0;
// Reports queue in the kernel while the reader is held up (a stalled daemon): hidraw
// keeps up to 63 per reader (a ring of 64) and drops newer ones once it is full.
constexpr std::size_t kKernelQueue = 63;

std::string find_hydra_path() {
  std::string path;
  hid_device_info* list = hid_enumerate(kVendorId, kProductId);
  for (auto* d = list; d && path.empty(); d = d->next)
    if (d->interface_number == kDataInterface && d->path) path = d->path;
  hid_free_enumeration(list);
  return path;
}

class HydraDriver final : public Driver {
 public:
  HydraDriver(HydraConfig config, DriverClock& clock) : config_(std::move(config)), clock_(clock) {}

  Result<void> run(SampleSink& sink, std::stop_token stop) override {
    if (hid_init() != 0) return fail("Razer Hydra: hidapi cannot start");
    const std::string path = config_.hid_path.empty() ? find_hydra_path() : config_.hid_path;
    if (path.empty())
      return fail(fmt::format("Razer Hydra: device not found (USB {:04x}:{:04x}, interface {}): is it plugged "
                              "in, and may this user open /dev/hidraw* (udev rule)?",
                              kVendorId, kProductId, kDataInterface));
    // hidapi opens whatever it is given, in blocking mode; only a hidraw node (a character
    // device) can be a Hydra, and a FIFO or a file there is named here instead.
    if (auto kind = require_character_device(path, "Razer Hydra: hid_path"); !kind) return kind;
    hid_device* dev = hid_open_path(path.c_str());
    if (!dev) return fail(fmt::format("Razer Hydra: cannot open {} (permissions?)", path));
    auto result = stream(dev, sink, stop);
    hid_close(dev);
    return result;
  }

 private:
  Result<void> stream(hid_device* dev, SampleSink& sink, std::stop_token stop) {
    const double period_s = 1.0 / config_.rate_hz;
    const auto motion = motion_mode_feature_report();
    auto last_report = clock_.now(), last_switch = Clock::time_point{};
    // Reports that do not parse are no sign of life: only a parsed one feeds the watchdog.
    ValidFrameWatchdog watchdog(config_.no_valid_frames_s, last_report);
    std::uint64_t bad_reports = 0;
    std::array<std::array<std::uint8_t, 64>, kKernelQueue> queued{};  // each read takes all that waits
    std::array<int, kKernelQueue> queued_size{};
    bool lost = false;
    while (!stop.stop_requested()) {
      const double silent_s = std::chrono::duration<double>(clock_.now() - last_report).count();
      if (silent_s > kModeSwitchRetry_s &&
          std::chrono::duration<double>(clock_.now() - last_switch).count() > kModeSwitchRetry_s) {
        hid_send_feature_report(dev, motion.data(), motion.size());
        last_switch = clock_.now();
      }
      if (auto expired = watchdog.expired(clock_.now())) {
        report_lost(sink);
        return fail(fmt::format("Razer Hydra: {} ({} reports that did not parse; controllers reported LOST)",
                                *expired, bad_reports));
      }
      const auto wait = clock_.io_timeout(stop, clock_.now() + kReadPoll, kReadPoll);
      const int n = hid_read_timeout(dev, queued[0].data(), queued[0].size(), static_cast<int>(wait.count()));
      if (n < 0) {
        report_lost(sink);
        return fail("Razer Hydra: device disconnected (controllers reported LOST)");
      }
      if (n == 0) {
        if (!lost && silent_s > config_.watchdog_periods * period_s) {
          report_lost(sink);
          lost = true;
        }
        continue;
      }
      queued_size[0] = n;
      std::size_t count = 1;
      for (; count < queued.size(); ++count) {  // what else waits, without waiting
        queued_size[count] = hid_read_timeout(dev, queued[count].data(), queued[count].size(), 0);
        if (queued_size[count] <= 0) break;  // none left (a disconnect shows at the next read)
      }
      // They were measured one report period apart, the last just now: a shared read
      // time would put all but the last too late, by up to the hold-up. Unless the
      // kernel's queue was full: then it dropped the newest, and these are of unknown age.
      const bool timed = count < kKernelQueue;
      if (!timed)
        sink.count_error(fmt::format("Razer Hydra: the reader was held up for {} reports or more and the kernel "
                                     "dropped the newer ones; the {} it kept are not published, their times unknown",
                                     kKernelQueue, count));
      const std::int64_t read_us = clock_.now_us();
      for (std::size_t k = 0; k < count; ++k) {
        auto report = parse_hydra_report({queued[k].data(), static_cast<std::size_t>(queued_size[k])});
        if (!report) {
          ++bad_reports;
          sink.count_error(report.error().message);
          continue;
        }
        last_report = clock_.now();
        watchdog.valid_frame(last_report);
        if (!timed) continue;
        lost = false;
        const auto periods_before_last = static_cast<double>(count - 1 - k);
        auto out = stream_.on_report(*report, read_us - std::llround(periods_before_last * period_s * 1e6));
        for (const auto& line : out.errors) sink.count_error(line);
        for (const auto& sample : out.samples) sink.pose(sample);
      }
    }
    return {};
  }

  void report_lost(SampleSink& sink) {
    for (const auto& sample : stream_.lost(clock_.now_us())) sink.pose(sample);
  }

  HydraConfig config_;
  DriverClock& clock_;
  HydraStream stream_{config_};
};

}  // namespace

std::unique_ptr<Driver> make_hydra_driver(const HydraConfig& config, DriverClock& clock) {
  return std::make_unique<HydraDriver>(config, clock);
}

}  // namespace covtrack::hydra
