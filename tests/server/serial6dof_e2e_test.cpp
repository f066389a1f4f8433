// Emulated serial trackers -> covtrackd (a separate process) -> an LCM subscriber here,
// inside a private network namespace: NEES against the emulators' truth for each
// protocol, isolation of a resetting unit from another device, and a pseudo-terminal
// that goes away mid-run.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>
#include <covtrack/pose_cov_t.hpp>

#include "covtrack/emulators/serial6dof/emulator.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "daemon_process.hpp"

using namespace covtrack;
using serial6dof::Model;

namespace {

std::string url_for(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=8388608";
}

std::string link_path(const std::string& name) {
  return ::testing::TempDir() + "/covtrack_e2e6_" + name + "_" + std::to_string(::getpid());
}

class Collector {
 public:
  explicit Collector(const std::string& url) : lcm_(url) {
    lcm_.subscribe("covtrack/pose/.*", &Collector::on_pose, this)->setQueueCapacity(1 << 20);
    lcm_.subscribe("covtrack/status/.*", &Collector::on_status, this)->setQueueCapacity(1000);
  }
  bool good() { return lcm_.good(); }
  void run_for(double seconds) {
    covtrack::test::handle_for(lcm_, seconds);
  }
  std::map<std::string, std::vector<pose_cov_t>> poses;  // by "device/sensor"
  std::map<std::string, device_status_t> status;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
    poses[m->device + "/" + m->sensor].push_back(*m);
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) {
    status[m->device] = *m;
  }
  lcm::LCM lcm_;
};

struct Emulated {
  std::string device;
  std::unique_ptr<emulate6dof::Emulator> emulator;
  std::map<std::string, Pose> truth;
};

Emulated emulate(const std::string& device, Model model, std::vector<int> stations,
                 double reset_time_s, double rate_hz = 0, double trouble_every_s = 0, double sway_m = 0,
                 emulate6dof::Emulator::TruthCallback on_truth = nullptr) {
  emulate6dof::EmulatorConfig c;
  c.model = model;
  c.link_path = link_path(device);
  c.stations = emulate6dof::default_stations(stations);
  c.reset_time_s = reset_time_s;
  c.rate_hz = rate_hz;
  c.trouble_every_s = trouble_every_s;
  c.sway_m = sway_m;
  c.seed = 11 + static_cast<std::uint64_t>(model);
  auto e = emulate6dof::Emulator::create(c);
  EXPECT_TRUE(e) << e.error().message;
  Emulated out{device, std::move(*e), {}};
  for (const auto& s : c.stations) out.truth[s.name] = s.T_source_receiver;
  out.emulator->start(std::move(on_truth));
  return out;
}

std::string device_table(const Emulated& e, const std::string& type, const std::string& extra) {
  std::string t = "[devices." + e.device + "]\ntype = \"" + type + "\"\nport = \"" +
                  e.emulator->device_path() + "\"\n" + extra;
  for (const auto& [name, pose] : e.truth)
    t += "[[devices." + e.device + ".stations]]\nnumber = " + name.substr(2) + "\nname = \"" + name + "\"\n";
  return t;
}

struct Nees {
  double mean = 0;
  int n = 0;
};

Nees nees_of(Collector& c, const Emulated& e) {
  Nees out;
  double sum = 0;
  for (const auto& [name, T_true] : e.truth)
    for (const auto& m : c.poses[e.device + "/" + name]) {
      if (m.status == pose_cov_t::STATUS_LOST) continue;
      const Vec6 err = boxminus(T_true, pose_of(m));
      sum += err.dot(body_covariance_of(m).inverse() * err);
      ++out.n;
    }
  out.mean = out.n ? sum / out.n : 0;
  return out;
}

}  // namespace

TEST(Serial6dofEndToEnd, EachProtocolThroughTheDaemonHasChiSquareNees) {
  const std::string url = url_for(7711);
  Collector c(url);
  ASSERT_TRUE(c.good());
  std::vector<Emulated> units;
  units.push_back(emulate("is900", Model::Is900, {1, 2}, 0.3, 100, 0.1));
  units.push_back(emulate("liberty", Model::Liberty, {1, 2}, 0.3, 100, 0.1));
  units.push_back(emulate("flock", Model::Flock, {1, 2}, 0.3, 100));
  const std::string common = "reset_time_s = 0.3\nrate_hz = 100\n";
  test::DaemonProcess daemon(device_table(units[0], "fastrak", common + "model = \"is900\"\n") +
                                 device_table(units[1], "liberty", common) +
                                 device_table(units[2], "flock", common), url);
  // Collect until every unit has 700 poses (3.5 s at 100 Hz with two stations, after its
  // reset) or 20 s pass. Not a fixed window from the daemon's start: a first open can be
  // refused and retried after the back-off (seen once in CI: EBUSY on a fresh emulator's
  // pseudo-terminal with no process holding it, 1.5 s lost), and the daemon handling
  // that is not what this test measures.
  const int kPoses = 700;
  const auto enough = [&] {
    for (const auto& u : units)
      if (nees_of(c, u).n < kPoses) return false;
    return true;
  };
  for (int waited = 0; waited < 40 && !enough(); ++waited) c.run_for(0.5);
  for (const auto& u : units) {
    const Nees n = nees_of(c, u);
    ASSERT_GE(n.n, kPoses) << u.device << " (within 20 s)";
    EXPECT_NEAR(n.mean, 6.0, 3.29 * std::sqrt(12.0 / n.n)) << u.device << " over " << n.n;
    std::cout << "[ NEES ] " << u.device << " through covtrackd: mean " << n.mean << " over " << n.n
              << " poses\n";
    ASSERT_TRUE(c.status.count(u.device)) << u.device;
    EXPECT_EQ(int{c.status[u.device].state}, int{device_status_t::STATE_RUNNING}) << u.device;
  }
}

TEST(Serial6dofEndToEnd, AResettingUnitDoesNotDelayAnotherDevice) {
  const std::string url = url_for(7712);
  Collector c(url);
  // A reset stalls for 2.5 s: a device held up by it would show a gap of seconds. The
  // bound is a quarter of that, far above the scheduling hiccups of a loaded 2-core
  // machine (up to 150 ms seen with four builds beside the suite).
  const double steady_rate_hz = 20;
  Emulated resetting = emulate("slow", Model::Fastrak, {1}, 2.5, 60);
  Emulated steady = emulate("steady", Model::Patriot, {1}, 0.3, steady_rate_hz);
  test::DaemonProcess daemon(
      "[daemon]\nrestart_backoff_initial_s = 0.1\n" +
          device_table(resetting, "fastrak", "reset_time_s = 2.5\nrate_hz = 60\n") +
          device_table(steady, "liberty", "model = \"patriot\"\nreset_on_start = false\nrate_hz = 20\n"),
      url);
  // Two resets of the first unit: the one at start-up, then one mid-run after it hangs
  // (watchdog, driver failure, restart with reset).
  // Wait for its first records: a reset takes 2.5 s, and more when the first opens fail
  // and the daemon backs off (seen once under a parallel ctest: open() then EBADF, a
  // suspected descriptor race in the serial transport, not yet understood).
  for (int waited = 0; waited < 30 && c.poses["slow/st1"].size() < 20; ++waited) c.run_for(0.5);
  const auto first_back = c.poses["slow/st1"].size();
  resetting.emulator->hang();
  c.run_for(5.0);

  const auto& slow = c.poses["slow/st1"];
  const auto& fast = c.poses["steady/st1"];
  ASSERT_GT(first_back, 0u) << "the resetting unit never came back from its first reset";
  ASSERT_GT(slow.size(), first_back + 30) << "the unit never came back from its second reset";
  EXPECT_GE(resetting.emulator->resets(), 2u);
  // Over the whole run, resets included, the steady device never stalls.
  std::int64_t max_gap_us = 0;
  for (std::size_t i = 1; i < fast.size(); ++i)
    max_gap_us = std::max(max_gap_us, fast[i].measurement_time_us - fast[i - 1].measurement_time_us);
  EXPECT_GE(fast.size(), 150u) << "the steady device should have reported through both resets";
  const double period_us = 1e6 / steady_rate_hz;
  EXPECT_LT(max_gap_us, 2.5e6 / 4) << "largest gap " << max_gap_us << " us";
  std::cout << "[ ISOLATION ] across 2 resets (2.5 s each) of another unit: " << fast.size()
            << " reports, largest gap " << max_gap_us / 1e3 << " ms = " << max_gap_us / period_us
            << " periods\n";
}

TEST(Serial6dofEndToEnd, PseudoTerminalClosedMidRunGivesLostThenRecovers) {
  const std::string url = url_for(7713);
  Collector c(url);
  const double rate_hz = 50;
  Emulated unit = emulate("unplugged", Model::Liberty, {1}, 0.2, rate_hz);
  test::DaemonProcess daemon(
      "[daemon]\nrestart_backoff_initial_s = 0.1\nrestart_backoff_max_s = 0.2\n" +
          device_table(unit, "liberty", "reset_time_s = 0.2\nrate_hz = 50\n"),
      url);
  // Up and streaming first (a refused first open costs a back-off, see above).
  for (int waited = 0; waited < 40 && c.poses["unplugged/st1"].size() < 25; ++waited) c.run_for(0.25);
  ASSERT_GE(c.poses["unplugged/st1"].size(), 25u) << "the unit never streamed within 10 s";
  const std::int64_t unplugged_us = now_us();
  unit.emulator->unplug();
  c.run_for(0.6);
  const std::int64_t replugged_us = now_us();
  unit.emulator->replug();
  c.run_for(2.0);

  const auto& msgs = c.poses["unplugged/st1"];
  std::int64_t first_lost_us = 0, oks_after = 0;
  for (const auto& m : msgs) {
    if (m.status == pose_cov_t::STATUS_LOST && !first_lost_us && m.measurement_time_us >= unplugged_us)
      first_lost_us = m.measurement_time_us;
    if (m.status != pose_cov_t::STATUS_LOST && m.measurement_time_us > replugged_us) ++oks_after;
  }
  ASSERT_GT(first_lost_us, 0) << "no LOST after the pseudo-terminal closed";
  EXPECT_LT(first_lost_us - unplugged_us, 2 * 1e6 / rate_hz);
  EXPECT_GT(oks_after, 25) << "no recovery after the pseudo-terminal came back";
  EXPECT_GE(c.status["unplugged"].restarts, 1);
  std::cout << "[ UNPLUG ] LOST " << (first_lost_us - unplugged_us) / 1e3 << " ms after the close ("
            << 2e3 / rate_hz << " ms = 2 periods); " << oks_after << " poses after the return\n";
}

TEST(Serial6dofEndToEnd, RecordsQueuedWhileTheDaemonIsHeldUpKeepTheirOwnTimes) {
  // A swaying receiver, and the daemon stopped (SIGSTOP) for 2 s while the unit streams:
  // about 5 KB of records queue, more than one read of a pseudo-terminal returns (4 KB).
  // They are read in one burst after the hold, and each must carry the time it was
  // measured (the driver times a burst one report period apart, the last just now), not
  // the burst's read time, or the poses are placed up to 2 s late, far from where the
  // receiver was at their stated time. Read in two parts, the first part would be timed
  // as if it ended now: 0.4 s late.
  const std::string url = url_for(7714);
  Collector c(url);
  const double rate_hz = 100, hold_s = 2.0;
  std::mutex truth_mutex;
  std::map<std::int64_t, Vec3> truth;  // the receiver's true position, by time
  Emulated unit = emulate("swaying", Model::Fastrak, {1}, 0.2, rate_hz, 0, 0.05, [&](const TruthSample& t) {
    std::lock_guard lock(truth_mutex);
    truth[t.measurement_time_us] = t.T_parent_child.translation();
  });
  // latency_s = 0: the emulator writes a record as it samples it.
  test::DaemonProcess daemon(device_table(unit, "fastrak", "reset_time_s = 0.2\nrate_hz = 100\nlatency_s = 0\n"), url);
  for (int waited = 0; waited < 40 && c.poses["swaying/st1"].size() < 50; ++waited) c.run_for(0.25);
  ASSERT_GE(c.poses["swaying/st1"].size(), 50u) << "the unit never streamed within 10 s";
  const std::int64_t held_us = now_us();
  kill(daemon.pid(), SIGSTOP);
  std::this_thread::sleep_for(std::chrono::duration<double>(hold_s));  // the hold itself, not a wait for a result
  kill(daemon.pid(), SIGCONT);
  const std::int64_t resumed_us = now_us();
  c.run_for(0.5);

  // The poses stated as measured during the hold, in the order they came: each against
  // the truth sample nearest to it in space (within 0.4 s of its stated time), whose time
  // is when it was measured.
  std::lock_guard lock(truth_mutex);
  // A burst read late shifts its times by that much (hiccups of up to 150 ms are seen on
  // a loaded 2-core machine); a split or untimed burst is off by 0.4 s or more.
  const double late_s = 0.2;
  int within_hold = 0, back_in_time = 0;
  double worst_s = 0;
  std::int64_t previous_us = 0;
  for (const auto& m : c.poses["swaying/st1"]) {
    if (m.status == pose_cov_t::STATUS_LOST || m.measurement_time_us < held_us || m.measurement_time_us > resumed_us)
      continue;
    ++within_hold;
    // A split burst steps back in time by its second part's length.
    const double step_s = static_cast<double>(m.measurement_time_us - previous_us) * 1e-6;
    if (previous_us && step_s < -late_s) ++back_in_time;
    previous_us = m.measurement_time_us;
    const Vec3 p = pose_of(m).translation();
    double best_d = INFINITY;
    std::int64_t best_us = 0;
    for (auto it = truth.lower_bound(m.measurement_time_us - 400'000);
         it != truth.end() && it->first < m.measurement_time_us + 400'000; ++it)
      if (const double d = (it->second - p).norm(); d < best_d) best_d = d, best_us = it->first;
    worst_s = std::max(worst_s, std::abs(static_cast<double>(m.measurement_time_us - best_us)) * 1e-6);
  }
  std::cout << "[ HELD UP ] " << within_hold << " poses stated as measured during the daemon's " << hold_s
            << " s hold, " << back_in_time << " over " << late_s << " s before the one before; largest gap to the truth's time "
            << worst_s * 1e3 << " ms\n";
  // About 200 records were measured in the hold; a burst read late shifts some of them
  // past its end.
  EXPECT_GE(within_hold, 150);
  EXPECT_EQ(back_in_time, 0);
  // A period of timing, one of matching in noise, and the burst's lateness.
  EXPECT_LE(worst_s, late_s);
}
