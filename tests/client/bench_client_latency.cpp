// Receive paths compared in one run, run by hand inside a network namespace:
//   tests/netns_run.sh build/tests/client/bench_client_latency [seconds per run, default 2] [rounds, default 3]
//                                                               [one receiver's name, to profile it alone]
// One lcm::LCM publisher sends pose messages of 10 streams at 10, 20, 50 and 100 kHz
// aggregate (paced every 100 us, so a few messages leave together at the higher rates);
// each receiver, with its own default settings, measures one-way latency (publish_time_us
// to its handler, same host clock) and counts what arrived:
//   raw LCM        an lcm::LCM instance and a handler (LCM's receive thread, then handle())
//   bare UDP       a multicast socket, poll() and recv() one datagram at a time, LCM's
//                  header skipped, the pose decoded: the floor
//   Subscriber     covtrack's Subscriber on udpm:// (its own socket, recvmmsg, no thread hop)
//   Sub via LCM    the Subscriber attached to an lcm::LCM instance (the path udpm:// took before)
// Rounds interleave the receivers so load on the machine falls on all of them alike;
// percentiles are over all rounds' samples. Figures are ratios against raw LCM.
#include <arpa/inet.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "pose_messages.hpp"

using namespace covtrack;
using steady = std::chrono::steady_clock;

namespace {
const std::string kUrl = "udpm://239.255.76.67:7721?ttl=0";  // every receiver with its defaults
constexpr int kStreams = 10;
constexpr auto kTick = std::chrono::microseconds(100);

double now_us_fine() {
  return std::chrono::duration<double, std::micro>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Sends kStreams streams at `rate` messages/s aggregate for `seconds`; returns the count.
std::int64_t publish(double rate, double seconds, const std::string& device) {
  prctl(PR_SET_TIMERSLACK, 1UL);  // ticks of 100 us, not the default 50 us slack
  lcm::LCM lcm(kUrl);
  std::vector<pose_cov_t> messages;
  std::vector<std::string> channels;
  for (int s = 0; s < kStreams; ++s) {
    messages.push_back(test::pose_message(device, "s" + std::to_string(s), 0));
    channels.push_back(pose_channel(device, "s" + std::to_string(s)));
  }
  const auto start = steady::now();
  const long ticks = static_cast<long>(seconds * 1e6 / kTick.count());
  const double per_tick = rate * kTick.count() / 1e6;
  std::int64_t sent = 0;
  double owed = 0;
  for (long tick = 0; tick < ticks; ++tick) {
    std::this_thread::sleep_until(start + tick * kTick);
    for (owed += per_tick; owed >= 1; owed -= 1, ++sent) {
      auto& m = messages[static_cast<std::size_t>(sent % kStreams)];
      m.publish_time_us = now_us();
      lcm.publish(channels[static_cast<std::size_t>(sent % kStreams)], &m);
      ++m.sequence;
    }
  }
  return sent;
}

struct Tally {
  std::vector<double> latency_us;  // written by the receiving thread only
  std::atomic<std::int64_t> arrived{0};  // read by the publishing thread
  std::int64_t sent = 0, received = 0;
  void add(double publish_time_us) {
    latency_us.push_back(now_us_fine() - publish_time_us);
    arrived.fetch_add(1, std::memory_order_relaxed);
  }
};

// Publishes while `receive(stop)` runs on this thread; after the publisher ends, waits
// for the stragglers until 300 ms pass without one.
void measure(Tally& t, double rate, double seconds, const std::string& device,
             const std::function<void(const std::atomic<bool>& stop)>& receive) {
  std::atomic<bool> stop{false};
  const std::int64_t before = t.arrived;
  std::thread pub([&] {
    t.sent += publish(rate, seconds, device);
    std::int64_t last = 0;
    do {
      last = t.arrived;
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
    } while (t.arrived != last);
    stop = true;
  });
  receive(stop);
  pub.join();
  t.received += t.arrived - before;
}

void raw_lcm(Tally& t, double rate, double seconds) {
  lcm::LCM lcm(kUrl);
  struct Handler {
    Tally* t;
    void on(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
      t->add(static_cast<double>(m->publish_time_us));
    }
  } h{&t};
  lcm.subscribe("covtrack/pose/raw/.*", &Handler::on, &h)->setQueueCapacity(1'000'000);
  measure(t, rate, seconds, "raw", [&](const std::atomic<bool>& stop) {
    pollfd p{lcm.getFileno(), POLLIN, 0};
    while (!stop)
      if (poll(&p, 1, 10) > 0) lcm.handle();
  });
}

void bare_udp(Tally& t, double rate, double seconds) {
  const sockaddr_in group = *parse_udpm(kUrl);
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const int one = 1;
  ip_mreq membership{group.sin_addr, {htonl(INADDR_ANY)}};
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  bind(fd, reinterpret_cast<const sockaddr*>(&group), sizeof group);
  setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership);
  static char datagram[65536];
  measure(t, rate, seconds, "bare", [&](const std::atomic<bool>& stop) {
    pollfd p{fd, POLLIN, 0};
    while (!stop) {
      if (poll(&p, 1, 10) <= 0) continue;
      const ssize_t n = recv(fd, datagram, sizeof datagram, MSG_DONTWAIT);
      const char* nul = n > 8 ? static_cast<const char*>(std::memchr(datagram + 8, 0, n - 8)) : nullptr;
      if (!nul || std::strncmp(datagram + 8, "covtrack/pose/bare/", 19) != 0) continue;
      pose_cov_t m;
      if (m.decode(nul + 1, 0, static_cast<int>(datagram + n - nul - 1)) > 0)
        t.add(static_cast<double>(m.publish_time_us));
    }
  });
  close(fd);
}

void subscriber(Tally& t, double rate, double seconds, bool via_lcm) {
  const std::string device = via_lcm ? "old" : "sub";
  auto sub = via_lcm ? client::Subscriber::attach(std::make_shared<lcm::LCM>(kUrl), {.pattern = device + "/.*"})
                     : client::Subscriber::open({.lcm_url = kUrl, .pattern = device + "/.*"});
  if (!sub) {
    std::fprintf(stderr, "%s\n", sub.error().message.c_str());
    return;
  }
  (void)(*sub)->on_pose(".*", [&](const client::TrackedTransform& tt) {
    t.add(static_cast<double>(tt.publish_time_us));
  });
  measure(t, rate, seconds, device, [](const std::atomic<bool>& stop) {
    while (!stop) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  });
  (*sub)->stop();
}

struct Percentiles {
  double p50 = 0, p99 = 0;
};
Percentiles percentiles(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v[v.size() * 99 / 100]};
}

long rmem(const char* name) {
  long v = -1;
  std::ifstream(std::string("/proc/sys/net/core/") + name) >> v;
  return v;
}
}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 2.0;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::string only = argc > 3 ? argv[3] : "";
  std::printf("LCM URL %s; net.core.rmem_default %ld, rmem_max %ld bytes\n", kUrl.c_str(), rmem("rmem_default"),
              rmem("rmem_max"));
  if (auto s = client::Subscriber::open({.lcm_url = kUrl}); s && (*s)->receive_buffer())
    std::printf("Subscriber receive buffer: asked %d, granted %d (kernel accounting) %s\n",
                (*s)->receive_buffer()->requested, (*s)->receive_buffer()->granted,
                (*s)->receive_buffer()->note.c_str());
  std::printf("%d streams, %.1f s per run, %d rounds interleaved\n\n", kStreams, seconds, rounds);
  const char* names[] = {"raw LCM", "bare UDP", "Subscriber", "Sub via LCM"};
  std::printf("%9s  %-12s %9s %9s %9s %9s %10s %10s\n", "rate/s", "receiver", "p50 us", "p99 us", "p50/raw",
              "p99/raw", "received", "lost");
  for (double rate : {10'000.0, 20'000.0, 50'000.0, 100'000.0}) {
    Tally t[4];
    const auto run = [&](int i) { return only.empty() || only == names[i]; };
    for (int round = 0; round < rounds; ++round) {
      if (run(0)) raw_lcm(t[0], rate, seconds);
      if (run(1)) bare_udp(t[1], rate, seconds);
      if (run(2)) subscriber(t[2], rate, seconds, false);
      if (run(3)) subscriber(t[3], rate, seconds, true);
    }
    const Percentiles raw = percentiles(t[0].latency_us);
    for (int i = 0; i < 4; ++i) {
      if (!run(i)) continue;
      const Percentiles p = percentiles(t[i].latency_us);
      std::printf("%9.0f  %-12s %9.1f %9.1f %9.2f %9.2f %10ld %10ld (%.3f%%)\n", rate, names[i], p.p50, p.p99,
                  p.p50 / raw.p50, p.p99 / raw.p99, static_cast<long>(t[i].received),
                  static_cast<long>(t[i].sent - t[i].received),
                  t[i].sent ? 100.0 * static_cast<double>(t[i].sent - t[i].received) / static_cast<double>(t[i].sent)
                            : 0.0);
    }
    std::fflush(stdout);
  }
  return 0;
}
