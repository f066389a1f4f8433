#pragma once
// Which processes have a device open, as `fuser` would say: for an open refused with
// EBUSY ("another program holds it exclusively"), the message can name the program.
#include <string>
#include <vector>

namespace covtrack::serial {

// "name (pid N)" for each process with a descriptor on the device that `path` names
// (symlinks followed). Processes whose descriptors this one may not read are not listed.
std::vector<std::string> processes_holding(const std::string& path);

}  // namespace covtrack::serial
