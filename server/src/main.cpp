// covtrackd: hosts tracker drivers and publishes their poses with covariances over LCM.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <set>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "config.hpp"
#include "covtrack/program/command_line.hpp"
#include "device_ownership.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "host.hpp"
#include "stop_signals.hpp"
#include "vrpn_server.hpp"

namespace {
using namespace covtrack::program;
constexpr const char* kSignalNote =
    "A stop signal while the config is read ends covtrackd at once, by that signal (status 130 or 143 in a "
    "shell); while it claims its devices (daemon.claim_wait_s), with code 0 and nothing started. Exit code 4 "
    "names the stuck device on the log; the daemon exits anyway. Exit code 1 also when another daemon already "
    "publishes every configured device (the log names it).";

}  // namespace

int main(int argc, char** argv) {
  // First of all: a config that blocks (a pipe nobody writes) must not make the daemon
  // deaf to SIGINT/SIGTERM.
  covtrack::server::end_at_once_on_stop_signal();

  CLI::App app{"covtrackd: tracker daemon publishing pose + covariance over LCM", "covtrackd"};
  std::string config_path, lcm_url, log_level = "info";
  bool check_only = false, print_schema = false, allow_duplicates = false;
  app.add_option("--config,-c", config_path, "daemon config (TOML; a file or a pipe), e.g. config/sim.toml");
  app.add_option("--lcm-url,-u", lcm_url, "LCM URL (overrides the config's daemon.lcm_url)");
  app.add_flag("--check", check_only, "validate the config, open every file it names (not devices: a serial port, camera or HID device may be plugged in later), and exit");
  app.add_flag("--print-schema", print_schema, "print the config schema (Markdown) and exit");
  app.add_flag("--allow-duplicate-publishers", allow_duplicates,
               "publish devices that another daemon already publishes (sets daemon.allow_duplicate_publishers)");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  add_conventions(app, kSignalNote);
  if (const auto code = parse_command_line(app, argc, argv)) return *code;
  spdlog::set_level(spdlog::level::from_str(log_level));

  if (print_schema) {
    std::cout << covtrack::server::config_schema_markdown();
    return 0;
  }
  if (config_path.empty()) {
    std::cerr << "covtrackd: --config FILE is required (try config/sim.toml)\n";
    return kExitUsageError;
  }
  // --check also opens the files the devices name (image sequences, videos, calibrations);
  // a start does not, as a file missing now may appear later and its driver retries it.
  auto config = covtrack::server::load_config(
      config_path, check_only ? covtrack::server::ResourceChecks::Run : covtrack::server::ResourceChecks::Skip);
  if (!config) {
    std::cerr << "covtrackd: the config has errors; nothing was started:\n"
              << config.error().message;
    return kExitUsageError;
  }
  if (check_only) {
    std::cout << config_path << ": OK, " << config->devices.size() << " device(s)\n";
    return 0;
  }
  if (config->devices.empty()) {
    std::cerr << "covtrackd: " << config_path << ": every device is disabled; nothing to run\n";
    return kExitUsageError;
  }

  // Before LCM or the host start a thread: from here on every thread inherits the mask.
  const sigset_t stop_signals = covtrack::server::block_stop_signals();
  const std::string url = covtrack::effective_lcm_url(lcm_url.empty() ? config->daemon.lcm_url : lcm_url);
  auto lcm = covtrack::open_lcm(url);
  if (!lcm) {
    std::cerr << "covtrackd: " << lcm.error().message << "\n";
    return kExitRuntimeError;
  }

  // Declared before the host: destroyed after the device threads that feed it.
  std::unique_ptr<covtrack::server::VrpnServer> vrpn_server;
  if (config->vrpn_server) {
    auto opened = covtrack::server::VrpnServer::open(*config->vrpn_server);
    if (!opened) {
      std::cerr << "covtrackd: " << opened.error().message << "\n";
      return kExitRuntimeError;
    }
    vrpn_server = std::move(*opened);
    vrpn_server->start();
  }
  covtrack::server::Host host(*config, **lcm);
  if (vrpn_server)
    host.tap_poses([server = vrpn_server.get()](const std::string& device, const covtrack::PoseSample& s) {
      server->offer(device, s);
    });

  // One publisher per device: claim them, and start only those no other daemon holds.
  std::vector<std::string> names;
  for (const auto& d : config->devices) names.push_back(d.name);
  const covtrack::server::ClaimSettings claim{config->daemon.claim_wait_s,
                                              config->daemon.allow_duplicate_publishers || allow_duplicates};
  auto ownership = covtrack::server::DeviceOwnership::open(
      **lcm, url, host.identity(), names, claim, [&host](const std::string& device, const std::string& why) {
        spdlog::error("covtrackd: device '{}' stopped: {}", device, why);
        if (!host.give_up(device)) covtrack::server::signal_nothing_left();
      });
  if (!ownership) {
    std::cerr << "covtrackd: " << ownership.error().message << "\n";
    return kExitRuntimeError;
  }
  std::optional<int> early_signal;
  const auto refused = (*ownership)->claim([&](std::chrono::milliseconds t) {
    early_signal = covtrack::server::wait_for_stop_signal(stop_signals, t);
    return !early_signal;
  });
  if (!refused) {  // LCM and a VRPN server may be up: a normal stop, before any device
    spdlog::info("covtrackd: {} while claiming the devices; none was started", *early_signal == SIGINT ? "SIGINT" : "SIGTERM");
    return 0;
  }
  std::set<std::string> not_started;
  for (const auto& [device, why] : *refused) {
    spdlog::error("covtrackd: device '{}' not started: {}", device, why);
    not_started.insert(device);
  }
  if (not_started.size() == names.size()) {
    std::cerr << "covtrackd: every configured device is published by another daemon; nothing was started\n";
    return kExitRuntimeError;
  }
  host.start(not_started);
  spdlog::info("covtrackd: {} device(s) publishing on {}{}", names.size() - not_started.size(), url,
               config->auth_key ? ", every message authenticated ([auth])" : "");

  const int signal = covtrack::server::wait_for_stop_signal(stop_signals);
  if (signal == covtrack::server::kNothingLeftSignal)
    spdlog::error("covtrackd: every device is now published by another daemon; stopping");
  else
    spdlog::info("covtrackd: {} received, stopping", signal == SIGINT ? "SIGINT" : "SIGTERM");
  if (const auto stuck = host.stop(); !stuck.empty()) {
    for (const auto& line : stuck) spdlog::error("covtrackd: {}; exiting anyway", line);
    spdlog::shutdown();  // flushes the log
    // Without unwinding: the host would wait for the stuck thread in its destructor.
    std::_Exit(kExitDeviceDidNotStop);
  }
  return signal == covtrack::server::kNothingLeftSignal ? kExitRuntimeError : 0;
}
