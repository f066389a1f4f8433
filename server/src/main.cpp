// covtrackd: hosts tracker drivers and publishes their poses with covariances over LCM.
#include <csignal>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "config.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "host.hpp"

namespace {
// Exit codes: 0 stopped by a signal, 1 could not start, 2 bad config or usage.
constexpr int kExitCannotStart = 1;
constexpr int kExitBadConfig = 2;
}  // namespace

int main(int argc, char** argv) {
  // Block the stop signals before any thread exists, so that every thread inherits the
  // mask and only sigwait() below receives them.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  CLI::App app{"covtrackd: tracker daemon publishing pose + covariance over LCM", "covtrackd"};
  std::string config_path, lcm_url, log_level = "info";
  bool check_only = false, print_schema = false;
  app.add_option("--config,-c", config_path, "daemon config (TOML), e.g. config/sim.toml");
  app.add_option("--lcm-url", lcm_url, "LCM URL (overrides the config's daemon.lcm_url)");
  app.add_flag("--check", check_only, "validate the config, open every file and device it names, and exit");
  app.add_flag("--print-schema", print_schema, "print the config schema (Markdown) and exit");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : kExitBadConfig;
  }
  spdlog::set_level(spdlog::level::from_str(log_level));

  if (print_schema) {
    std::cout << covtrack::server::config_schema_markdown();
    return 0;
  }
  if (config_path.empty()) {
    std::cerr << "covtrackd: --config FILE is required (try config/sim.toml)\n";
    return kExitBadConfig;
  }
  // --check also opens what the devices name (files, folders, device nodes); a start
  // does not, as a device missing now may appear later and its driver retries it.
  auto config = covtrack::server::load_config(
      config_path, check_only ? covtrack::server::ResourceChecks::Run : covtrack::server::ResourceChecks::Skip);
  if (!config) {
    std::cerr << "covtrackd: the config has errors; nothing was started:\n"
              << config.error().message;
    return kExitBadConfig;
  }
  if (check_only) {
    std::cout << config_path << ": OK, " << config->devices.size() << " device(s)\n";
    return 0;
  }
  if (config->devices.empty()) {
    std::cerr << "covtrackd: " << config_path << ": every device is disabled; nothing to run\n";
    return kExitBadConfig;
  }

  const std::string url = covtrack::effective_lcm_url(lcm_url.empty() ? config->daemon.lcm_url : lcm_url);
  auto lcm = covtrack::open_lcm(url);
  if (!lcm) {
    std::cerr << "covtrackd: " << lcm.error().message << "\n";
    return kExitCannotStart;
  }

  covtrack::server::Host host(*config, **lcm);
  host.start();
  spdlog::info("covtrackd: {} device(s) publishing on {}", config->devices.size(), url);

  int signal = 0;
  sigwait(&stop_signals, &signal);
  spdlog::info("covtrackd: {} received, stopping", signal == SIGINT ? "SIGINT" : "SIGTERM");
  host.stop();
  return 0;
}
