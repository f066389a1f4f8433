// `covtrack emulate-lenz`: a Lenz Digital Plus train set behind an LI101F or LI-USB on a
// pseudo-terminal, for covtrackd's "lenz" driver; the true vehicle poses go out on the
// truth channel (covtrack/truth/<device>/<vehicle>).
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>

#include <fmt/core.h>

#include <covtrack/truth_pose_t.hpp>

#include "commands.hpp"
#include "covtrack/emulators/lenz/lenz_emulator.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "layout_config.hpp"
#include "stop_signal.hpp"

namespace covtrack::cli {
namespace {

struct EmulateLenzArgs {
  std::string layout = "config/lenz_layout.toml";
  std::string link = "/tmp/covtrack-lenz";
  std::string interface = "li101f";
  std::string profile = "0.3:10,0.1:6,0:4,0.25:8";
  double accel_mps2 = 0;
  std::string device = "train";
  std::string parent_frame = "table";
  double truth_hz = 50;
  bool no_truth = false;
  std::optional<double> duration_s;
  std::string lcm_url;
};

int run_emulate_lenz(const EmulateLenzArgs& args) {
  auto layout = lenz::load_layout(args.layout);
  if (!layout) {
    fmt::print(stderr, "covtrack emulate-lenz: {}\n", layout.error().message);
    return 2;
  }
  auto profile = lenz::parse_speed_profile(args.profile);
  if (!profile) {
    fmt::print(stderr, "covtrack emulate-lenz: --profile: {}\n", profile.error().message);
    return 2;
  }
  if (!is_valid_name(args.device)) {
    fmt::print(stderr, "covtrack emulate-lenz: --device '{}' is not a valid device name\n", args.device);
    return 2;
  }
  std::unique_ptr<lcm::LCM> lcm;
  if (!args.no_truth) {
    auto opened = open_lcm(args.lcm_url);
    if (!opened) {
      fmt::print(stderr, "covtrack emulate-lenz: {}\n", opened.error().message);
      return 1;
    }
    lcm = std::move(*opened);
  }
  lenz::LenzEmulatorOptions options;
  options.layout = std::make_shared<const lenz::TrackLayout>(std::move(*layout));
  options.interface = args.interface == "liusb" ? lenz::Interface::LiUsb : lenz::Interface::Li101f;
  options.profile = *profile;
  options.accel_mps2 = args.accel_mps2;
  options.link_path = args.link;
  options.parent_frame = args.parent_frame;
  options.truth_hz = args.truth_hz;
  auto emulator = lenz::LenzEmulator::create(options);
  if (!emulator) {
    fmt::print(stderr, "covtrack emulate-lenz: {}\n", emulator.error().message);
    return 1;
  }
  std::map<std::string, std::int64_t> sequences;
  auto publish_truth = [&](const TruthSample& s) {
    truth_pose_t msg;
    msg.measurement_time_us = s.measurement_time_us;
    msg.device = args.device;
    msg.sensor = s.sensor;
    msg.parent_frame = s.parent_frame;
    msg.child_frame = s.child_frame;
    set_pose(msg, s.T_parent_child);
    const std::string channel = truth_channel(args.device, s.sensor);
    msg.sequence = sequences[channel]++;
    lcm->publish(channel, &msg);
  };

  install_stop_signals();
  // Scripts and tests wait for this line: from here on the port can be opened.
  fmt::print(stderr, "covtrack emulate-lenz: {} on {} ({}), {} sections, {:.2f} m loop, profile cycle {:.1f} s\n",
             args.interface, args.link, (*emulator)->slave_path(), options.layout->sections().size(),
             options.layout->length_m(), (*emulator)->motion().cycle_s());
  std::jthread worker([&](std::stop_token stop) {
    (*emulator)->run(stop, lcm ? std::function<void(const TruthSample&)>(publish_truth) : nullptr);
  });
  const auto start = std::chrono::steady_clock::now();
  while (!stop_requested()) {
    if (args.duration_s && std::chrono::steady_clock::now() - start > std::chrono::duration<double>(*args.duration_s))
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  worker.request_stop();
  worker.join();
  fmt::print(stderr, "covtrack emulate-lenz: {} requests answered, {} feedback broadcasts\n",
             (*emulator)->requests_answered(), (*emulator)->broadcasts_sent());
  return 0;
}

}  // namespace

void add_emulate_lenz_command(CLI::App& app) {
  auto args = std::make_shared<EmulateLenzArgs>();
  auto* cmd = app.add_subcommand("emulate-lenz", "Emulate a Lenz Digital Plus train set (LI101F / LI-USB) on a "
                                                 "pseudo-terminal, publishing the true poses");
  cmd->add_option("--layout", args->layout, "Track layout file")->capture_default_str();
  cmd->add_option("--link", args->link, "Path of the link to the pseudo-terminal (the driver's port)")
      ->capture_default_str();
  cmd->add_option("--interface", args->interface, "li101f or liusb")
      ->check(CLI::IsMember({"li101f", "liusb"}))
      ->capture_default_str();
  cmd->add_option("--profile", args->profile, "Speed profile speed_mps:hold_s,... (repeats; ends with a stop)")
      ->capture_default_str();
  cmd->add_option("--accel", args->accel_mps2, "Acceleration, m/s^2 (default: 80% of the layout's max_accel_mps2)")
      ->check(program::non_negative());
  cmd->add_option("--device", args->device, "Device name of the daemon's lenz driver (truth channel names)")
      ->capture_default_str();
  cmd->add_option("--parent-frame", args->parent_frame, "Frame of the truth poses")->capture_default_str();
  cmd->add_option("--truth-hz", args->truth_hz, "Truth poses per second per vehicle")
      ->check(program::in_range(0.1, 1000.0))
      ->capture_default_str();
  cmd->add_flag("--no-truth", args->no_truth, "Publish nothing on LCM");
  cmd->add_option("--duration,-d", args->duration_s, "Stop after S seconds")->check(program::positive());
  cmd->add_option("--lcm-url,-u", args->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or LCM's)");
  cmd->callback([args] {
    if (const int code = run_emulate_lenz(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
