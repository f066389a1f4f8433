#pragma once
// Runs a shell command line and keeps what it printed and how it ended: for the tests
// that run the project's programs (`covtrack`, `covtrackd`).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace covtrack::testing {

struct CliRun {
  int exit_code;    // -1: it did not exit normally (a signal), or could not be started
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

}  // namespace covtrack::testing
