// Razer Hydra input reports: the input as a sequence of (time step, 52-byte report)
// records, each parsed, then passed through the driver's stream (hemisphere choice and
// plausibility gate) as the driver does; the whole input is parsed as one report too.
#include "fuzz/fuzz_support.hpp"
#include "hydra_report.hpp"
#include "hydra_stream.hpp"

using namespace covtrack;
using namespace covtrack::hydra;

namespace {

void check_report(const HydraReport& report) {
  for (const ControllerState& c : report.controllers) {
    FUZZ_CHECK(c.position_m.allFinite() && c.orientation.coeffs().allFinite());
    FUZZ_CHECK(std::abs(c.orientation.norm() - 1.0) < 0.1);
    FUZZ_CHECK(std::abs(c.joystick_x) <= 1.0 && std::abs(c.joystick_y) <= 1.0);
    FUZZ_CHECK(c.trigger >= 0.0 && c.trigger <= 1.0);
  }
}

void check_sample(const PoseSample& s) {
  FUZZ_CHECK(s.T_parent_child.matrix().allFinite());
  if (s.status != TrackingStatus::Lost) {
    FUZZ_CHECK(s.covariance.allFinite());
    FUZZ_CHECK(s.covariance.isApprox(s.covariance.transpose()));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (const auto whole = parse_hydra_report({data, size})) check_report(*whole);
  HydraConfig config;
  config.device = "hydra";
  config.covariance = hydra_default_covariance();
  HydraStream stream(config);
  std::int64_t time_us = 0;
  for (std::size_t at = 0; at + 1 + kReportSize <= size; at += 1 + kReportSize) {
    time_us += std::int64_t(data[at]) * 1000;  // 0 to 255 ms since the last report
    const auto report = parse_hydra_report({data + at + 1, kReportSize});
    if (!report) {
      FUZZ_CHECK(!report.error().message.empty());
      continue;
    }
    check_report(*report);
    for (const PoseSample& s : stream.on_report(*report, time_us).samples) check_sample(s);
  }
  for (const PoseSample& s : stream.lost(time_us)) check_sample(s);
  return 0;
}
