#pragma once
// Which processes have a device open, as `fuser` would say: for an open refused with
// EBUSY ("another program holds it exclusively"), the message can name the program.
#include <string>
#include <vector>

namespace covtrack::serial {

// "covtrackd (pid 1234)": the name from /proc/<pid>/comm, or "pid 1234" when it cannot be read.
std::string describe_process(int pid);

// describe_process() for each process with a descriptor on the device that `path` names
// (symlinks followed). Processes whose descriptors this one may not read are not listed.
std::vector<std::string> processes_holding(const std::string& path);

}  // namespace covtrack::serial
