// `covtrack emulate-6dof --protocol fastrak|liberty|flock --link PATH`: an emulated
// serial tracker behind a pseudo-terminal, for demos and tests without hardware. The
// daemon's config names PATH as the port; the emulator publishes the noise-free poses
// on covtrack/truth/<device>/<station name>.
#include <chrono>
#include <iostream>
#include <memory>
#include <mutex>
#include <map>
#include <thread>

#include <fmt/format.h>

#include <covtrack/truth_pose_t.hpp>

#include "commands.hpp"
#include "covtrack/emulators/serial6dof/emulator.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "device_model.hpp"
#include "stop_signal.hpp"

namespace covtrack::cli {
namespace {

struct EmulateArgs {
  std::string protocol;
  std::string model;
  std::string link;
  std::vector<int> stations = {1};
  double rate_hz = 0;
  double reset_time_s = -1;
  std::uint64_t seed = 1;
  double trouble_every_s = 0;
  double duration_s = 0;
  std::string device;
  std::string lcm_url;
  bool no_truth = false;
};

std::optional<serial6dof::Model> model_of(const EmulateArgs& a) {
  using serial6dof::Model;
  const std::string m = a.model.empty() ? a.protocol : a.model;
  for (Model model : {Model::Fastrak, Model::Is900, Model::Liberty, Model::Patriot, Model::Flock})
    if (serial6dof::model_spec(model).name == m &&
        serial6dof::to_string(serial6dof::protocol_of(model)) == a.protocol)
      return model;
  return std::nullopt;
}

int run_emulate(const EmulateArgs& args) {
  const auto model = model_of(args);
  if (!model) {
    fmt::print(stderr, "covtrack emulate-6dof: model '{}' does not speak protocol '{}' "
               "(fastrak: fastrak, is900; liberty: liberty, patriot; flock: flock)\n",
               args.model, args.protocol);
    return 2;
  }
  const std::string device = args.device.empty() ? args.protocol : args.device;
  if (!is_valid_name(device)) {
    fmt::print(stderr, "covtrack emulate-6dof: '{}' is not a valid device name\n", device);
    return 2;
  }
  std::unique_ptr<lcm::LCM> lcm;
  if (!args.no_truth) {
    auto opened = open_lcm(args.lcm_url);
    if (!opened) {
      fmt::print(stderr, "covtrack emulate-6dof: {}\n", opened.error().message);
      return 1;
    }
    lcm = std::move(*opened);
  }

  emulate6dof::EmulatorConfig config;
  config.model = *model;
  config.link_path = args.link;
  config.stations = emulate6dof::default_stations(args.stations);
  config.rate_hz = args.rate_hz;
  config.reset_time_s = args.reset_time_s;
  config.seed = args.seed;
  config.trouble_every_s = args.trouble_every_s;
  auto emulator = emulate6dof::Emulator::create(config);
  if (!emulator) {
    fmt::print(stderr, "covtrack emulate-6dof: {}\n", emulator.error().message);
    return 1;
  }

  std::map<std::string, std::int64_t> sequence;  // per truth stream
  (*emulator)->start([&](const TruthSample& t) {
    if (!lcm) return;
    truth_pose_t msg;
    msg.measurement_time_us = t.measurement_time_us;
    msg.sequence = sequence[t.sensor]++;
    msg.device = device;
    msg.sensor = t.sensor;
    msg.parent_frame = t.parent_frame;
    msg.child_frame = t.child_frame;
    set_pose(msg, t.T_parent_child);
    lcm->publish(truth_channel(device, t.sensor), &msg);
  });
  std::string stations;
  for (int s : args.stations) stations += (stations.empty() ? "" : ",") + std::to_string(s);
  fmt::print("covtrack emulate-6dof: {} ({}) on {}, stations {}\n", args.protocol,
             serial6dof::model_spec(*model).name, (*emulator)->device_path(), stations);
  std::cout.flush();
  std::fflush(stdout);

  install_stop_signals();
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(args.duration_s);
  while (!stop_requested() && (args.duration_s <= 0 || std::chrono::steady_clock::now() < end))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  (*emulator)->stop();
  fmt::print("covtrack emulate-6dof: {} records sent, {} resets\n", (*emulator)->records_sent(),
             (*emulator)->resets());
  return 0;
}

}  // namespace

void add_emulate_6dof_command(CLI::App& app) {
  auto args = std::make_shared<EmulateArgs>();
  auto* cmd = app.add_subcommand("emulate-6dof", "Emulate a serial 6-DOF tracker on a pseudo-terminal");
  cmd->add_option("--protocol", args->protocol, "fastrak, liberty or flock")
      ->required()->check(CLI::IsMember({"fastrak", "liberty", "flock"}));
  cmd->add_option("--model", args->model,
                  "fastrak or is900 (protocol fastrak), liberty or patriot (liberty), flock; "
                  "default: the protocol's name");
  cmd->add_option("--link", args->link, "path of the symbolic link to the pseudo-terminal "
                  "(the daemon config's port)")->required();
  cmd->add_option("--stations", args->stations, "station numbers (Flock: bird addresses)")
      ->delimiter(',');
  cmd->add_option("--rate-hz", args->rate_hz, "records per second per station (default: the model's)")
      ->check(program::in_range(0.1, 10000.0));
  cmd->add_option("--reset-time-s", args->reset_time_s, "how long a reset takes (default: the model's)")
      ->check(program::in_range(0.0, 120.0));
  cmd->add_option("--seed", args->seed, "noise seed");
  cmd->add_option("--trouble-every-s", args->trouble_every_s,
                  "flag one record set this often (status letter / error code), with inflated noise")
      ->check(program::in_range(0.0, 1e6));
  cmd->add_option("--duration,-d", args->duration_s, "stop after S seconds (default: until Ctrl-C)");
  cmd->add_option("--device", args->device, "device name for the truth channels (default: the protocol)");
  cmd->add_option("--lcm-url,-u", args->lcm_url, "LCM URL for the truth (default: $LCM_DEFAULT_URL or LCM's)");
  cmd->add_flag("--no-truth", args->no_truth, "do not publish the truth (no LCM at all)");
  cmd->callback([args] {
    if (const int rc = run_emulate(*args); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace covtrack::cli
