#pragma once
// A SampleSink that keeps what a driver reports, for tests that run a driver directly.
#include <mutex>
#include <vector>

#include "covtrack/devices/driver.hpp"

namespace covtrack::test {

class CaptureSink : public SampleSink {
 public:
  void pose(const PoseSample& s) override { std::lock_guard l(m); poses.push_back(s); }
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
