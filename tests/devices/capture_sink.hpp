#pragma once
// A SampleSink that keeps what a driver reports, for tests that run a driver directly.
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "covtrack/protocol/pose_message.hpp"

namespace covtrack::test {

// A LOST report's covariance as the protocol states it: +inf on the diagonal and exactly
// 0 elsewhere, never NaN (consumers that do not special-case LOST read it as is).
inline void expect_lost_covariance(const Mat6& cov) {
  EXPECT_FALSE(cov.hasNaN()) << "LOST covariance with NaN entries:\n" << cov;
  EXPECT_TRUE(cov == lost_covariance()) << "LOST covariance is not diag(+inf):\n" << cov;
}

class CaptureSink : public SampleSink {
 public:
  // Every driver test checks the LOST convention on every LOST sample it captures.
  void pose(const PoseSample& s) override {
    if (s.status == TrackingStatus::Lost) expect_lost_covariance(s.covariance);
    std::lock_guard l(m);
    poses.push_back(s);
  }
  void truth(const TruthSample& s) override { std::lock_guard l(m); truths.push_back(s); }
  void raw(ByteDirection, const std::uint8_t* d, std::size_t n) override {
    std::lock_guard l(m);
    raw_bytes.insert(raw_bytes.end(), d, d + n);
  }
  void count_error(const std::string&) override { ++errors; }
  void count_resync() override { ++resyncs; }
  void count_drop() override { ++drops; }

  std::mutex m;
  std::vector<PoseSample> poses;
  std::vector<TruthSample> truths;
  std::vector<std::uint8_t> raw_bytes;
  int errors = 0, resyncs = 0, drops = 0;
};

}  // namespace covtrack::test
