#pragma once
// The exit codes of both programs, covtrackd and covtrack (README.md, "Exit codes"), so
// that scripts and service managers can tell a typo from a broken recording.
namespace covtrack::program {

enum ExitCode : int {
  kExitOk = 0,
  kExitRuntimeError = 1,  // something failed while running: LCM, a file that cannot be written, a camera
  kExitUsageError = 2,    // the command line or a config/scene file is wrong; nothing (or nothing more) was done
  kExitDamagedInput = 3,  // an input is damaged (a broken log, a corrupt image or calibration file)
  kExitDeviceDidNotStop = 4,  // covtrackd: stopped, but a device's thread outlived daemon.stop_timeout_s
};

// The table for --help footers.
inline constexpr const char* kExitCodesHelp =
    "Exit codes: 0 ok; 1 runtime error; 2 usage or config error; 3 damaged input (a broken log, a corrupt "
    "file); 4 covtrackd only: stopped, but a device's thread did not end within daemon.stop_timeout_s.";

}  // namespace covtrack::program
