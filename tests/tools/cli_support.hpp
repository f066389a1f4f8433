#pragma once
// Shared by the tests that run the `covtrack` command: a run with its output and exit
// code, and containment in a polygon as `covtrack regions --json` prints it.
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

namespace covtrack::testing {

struct CliRun {
  int exit_code;
  std::string out;  // stdout and stderr together
};

// A shell command line, stderr with stdout.
inline CliRun run_command(const std::string& command) {
  const std::string cmd = command + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) out.append(buf.data(), n);
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// `covtrack ARGS`, with `env_prefix` (e.g. "env -u DISPLAY") before it.
inline CliRun run_covtrack(const std::string& args, const std::string& env_prefix = "") {
  return run_command(env_prefix + " " + std::string(COVTRACK_CLI) + " " + args);
}

// Inside a counter-clockwise convex polygon [[u, v], ...] (in u, v arithmetic), or within
// `tolerance` px of it.
inline bool json_polygon_contains(const nlohmann::json& polygon, double u, double v, double tolerance) {
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double au = polygon[i][0], av = polygon[i][1];
    const double bu = polygon[(i + 1) % n][0], bv = polygon[(i + 1) % n][1];
    if ((bu - au) * (v - av) - (bv - av) * (u - au) < -tolerance * std::hypot(bu - au, bv - av)) return false;
  }
  return n >= 3;
}

}  // namespace covtrack::testing
