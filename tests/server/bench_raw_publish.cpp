// Baseline for the daemon-CPU benchmark: the least a publisher of the same streams can
// do. Encodes and publishes pose_cov_t for N streams at R Hz with plain LCM, paced like
// the sim driver, for S seconds. Usage: bench_raw_publish URL STREAMS RATE_HZ SECONDS
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/pose_cov_t.hpp>

int main(int argc, char** argv) {
  if (argc != 5) return 2;
  lcm::LCM lcm(argv[1]);
  const int streams = std::atoi(argv[2]);
  const double rate = std::atof(argv[3]);
  const double seconds = std::atof(argv[4]);
  covtrack::pose_cov_t msg{};
  msg.device = "raw";
  msg.orientation_wxyz[0] = 1;
  using clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1 / rate));
  const auto start = clock::now();
  for (long tick = 0; tick < static_cast<long>(seconds * rate); ++tick) {
    std::this_thread::sleep_until(start + tick * period);
    for (int s = 0; s < streams; ++s) {
      msg.sensor = "s" + std::to_string(s);
      msg.sequence = tick;
      lcm.publish("covtrack/pose/raw/" + msg.sensor, &msg);
    }
  }
  return 0;
}
