#pragma once
// OpenCV 4.6's FileStorage (Debian 12) loops forever on some damaged YAML (an indented
// map, then "--" and a dedented "-0" is enough) and recurses without a limit: faults no
// text check can rule out (calibration_text.hpp rules out the ones it can) and no caller
// can catch. So a calibration file is read in a child process: one that runs past a time
// limit is killed, one that crashes is reported, and the caller's process (the daemon,
// a viewer, a Python session) carries on with an error.
#include <chrono>
#include <functional>
#include <string>

#include "covtrack/protocol/camera.hpp"

namespace covtrack {

inline constexpr std::chrono::seconds kCalibrationReadLimit{10};

// `read` run in a forked child, its camera or error sent back as it was; the errors of the
// child itself (stopped, crashed) name `file`. Where no child can be made (no pipe, no
// fork), `read` runs here.
Result<Camera> read_isolated(const std::function<Result<Camera>()>& read, const std::string& file,
                             std::chrono::milliseconds limit = kCalibrationReadLimit);

}  // namespace covtrack
