// Benchmarks of the subscriber, run by hand inside a network namespace:
//   tests/netns_run.sh build-client/tests/client/bench_client_latency
// Two places drop under load: the socket receive buffer (the URL's recv_buf_size, capped
// by net.core.rmem_max, which an unprivileged namespace cannot raise) and LCM's
// per-subscription queue (raised by the Subscriber).
// 1. publish -> callback latency at 10 sensors x 1 kHz: the Subscriber against a plain
//    LCM handler, both measured in this run.
// 2. the highest aggregate rate the Subscriber receives with no sequence gap.
#include <algorithm>
#include <fstream>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include <poll.h>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"

using namespace covtrack;
using clock_type = std::chrono::steady_clock;

namespace {
const std::string kUrl = "udpm://239.255.76.67:7721?ttl=0&recv_buf_size=8388608";
constexpr int kStreams = 10;

double now_us_fine() {
  return std::chrono::duration<double, std::micro>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Publishes kStreams streams at `total_rate` messages/s in 1 ms bursts for `seconds`.
std::int64_t publish(double total_rate, double seconds, const std::string& device) {
  lcm::LCM lcm(kUrl);
  pose_cov_t m{};
  m.device = device;
  m.orientation_wxyz[0] = 1;
  for (int i = 0; i < 6; ++i) m.covariance[7 * i] = 1e-6;
  std::vector<std::string> channels;
  for (int s = 0; s < kStreams; ++s) channels.push_back(pose_channel(device, "s" + std::to_string(s)));
  const auto start = clock_type::now();
  const long ticks = static_cast<long>(seconds * 1000);
  const double per_tick = total_rate / 1000.0;
  std::int64_t sent = 0;
  double owed = 0;
  for (long tick = 0; tick < ticks; ++tick) {
    std::this_thread::sleep_until(start + std::chrono::milliseconds(tick));
    for (owed += per_tick; owed >= 1; owed -= 1, ++sent) {
      const int s = static_cast<int>(sent % kStreams);
      m.sensor = "s" + std::to_string(s);
      m.sequence = sent / kStreams;
      m.publish_time_us = now_us();
      lcm.publish(channels[s], &m);
    }
  }
  return sent;
}

struct Percentiles {
  double p50, p99;
};
Percentiles percentiles(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v[v.size() * 99 / 100]};
}

std::vector<double> raw_lcm_latency(double seconds) {
  lcm::LCM lcm(kUrl);
  std::vector<double> lat;
  struct Handler {
    std::vector<double>* lat;
    void on(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
      lat->push_back(now_us_fine() - static_cast<double>(m->publish_time_us));
    }
  } h{&lat};
  lcm.subscribe("covtrack/pose/raw/.*", &Handler::on, &h)->setQueueCapacity(100000);
  std::atomic<bool> done{false};
  std::thread pub([&] { publish(kStreams * 1000.0, seconds, "raw"); done = true; });
  pollfd pfd{lcm.getFileno(), POLLIN, 0};
  while (!done) if (poll(&pfd, 1, 10) > 0) lcm.handle();
  pub.join();
  return lat;
}

std::vector<double> subscriber_latency(double seconds) {
  auto sub = client::Subscriber::open({.lcm_url = kUrl, .pattern = "sub/.*"});
  std::vector<double> lat;
  (void)(*sub)->on_pose(".*", [&](const client::TrackedTransform& t) {
    lat.push_back(now_us_fine() - static_cast<double>(t.publish_time_us));
  });
  publish(kStreams * 1000.0, seconds, "sub");
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  (*sub)->stop();
  return lat;
}
}  // namespace

long rmem_max() {
  long v = -1;
  std::ifstream("/proc/sys/net/core/rmem_max") >> v;
  return v;
}

int main() {
  std::printf("LCM URL %s, net.core.rmem_max %ld bytes (caps recv_buf_size)\n", kUrl.c_str(), rmem_max());
  std::printf("1. publish -> callback latency, %d sensors x 1 kHz over udpm (3 s each)\n", kStreams);
  const auto raw = percentiles(raw_lcm_latency(3));
  const auto ours = percentiles(subscriber_latency(3));
  std::printf("   plain LCM handler:   p50 %6.1f us   p99 %6.1f us\n", raw.p50, raw.p99);
  std::printf("   covtrack Subscriber: p50 %6.1f us   p99 %6.1f us\n", ours.p50, ours.p99);
  std::printf("   ratio Subscriber / plain: p50 %.2f   p99 %.2f\n", ours.p50 / raw.p50, ours.p99 / raw.p99);

  std::printf("2. aggregate rate without sequence gaps (%d streams, 2 s per step)\n", kStreams);
  double best = 0;
  for (double rate : {10000.0, 20000.0, 40000.0, 60000.0, 80000.0, 160000.0}) {
    auto sub = client::Subscriber::open({.lcm_url = kUrl, .pattern = "rate/.*"});
    const auto t0 = clock_type::now();
    const std::int64_t sent = publish(rate, 2, "rate");
    const double sent_rate = sent / std::chrono::duration<double>(clock_type::now() - t0).count();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    std::int64_t received = 0, lost = 0;
    for (const auto& s : (*sub)->streams()) {
      received += s.counters.received;
      lost += s.counters.lost;
    }
    (*sub)->stop();
    // Sequence gaps seen by the Subscriber, plus messages missing at the end of a stream
    // (after its last received one), which no gap reveals.
    std::printf("   %7.0f msg/s (achieved %7.0f): sent %7ld received %7ld gaps %ld missing %ld%s\n", rate,
                sent_rate, static_cast<long>(sent), static_cast<long>(received), static_cast<long>(lost),
                static_cast<long>(sent - received), received == sent ? "" : "  <- loss");
    if (received != sent) break;
    best = rate;
  }
  std::printf("   highest rate with 0 gaps: %.0f msg/s\n", best);
  return 0;
}
