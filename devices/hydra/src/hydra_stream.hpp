#pragma once
// From parsed Hydra reports to the two controllers' samples: each position's sign
// resolved by continuity, then each pose checked by the plausibility gate
// (motion_gate.hpp). USB's checksum keeps the bytes intact, but a magnetic tracker can
// still report a pose the hand never took: metal or a second field near the base bends
// it, and a wrong hemisphere choice mirrors it through the base. Such a jump is dropped
// (and counted), a surprising one published DEGRADED with its covariance widened.
// Pure: times are passed in.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "covtrack/devices/motion_gate.hpp"
#include "hydra_report.hpp"

namespace covtrack::hydra {

class HydraStream {
 public:
  explicit HydraStream(const HydraConfig& config);

  struct Out {
    std::vector<PoseSample> samples;  // to publish
    std::vector<std::string> errors;  // dropped poses, one line each
  };
  Out on_report(const HydraReport& report, std::int64_t time_us);
  // Both controllers LOST (infinite covariance), at their last published poses.
  std::vector<PoseSample> lost(std::int64_t time_us);

 private:
  HydraConfig config_;
  HemisphereTracker hemisphere_;
  std::array<MotionGate, 2> gates_;
  std::array<Pose, 2> last_ = {Pose::Identity(), Pose::Identity()};
};

}  // namespace covtrack::hydra
