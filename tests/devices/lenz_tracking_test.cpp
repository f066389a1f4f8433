// The track layout model and the dead reckoning, without any I/O: the emulator's exact
// train motion drives the occupancy (with random detection latency), and the estimate
// is checked against the true position at every step.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <fstream>
#include <numbers>
#include <iterator>
#include <random>

#include <Eigen/Eigenvalues>
#include <Eigen/Cholesky>

#include "capture_sink.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/emulators/lenz/train_motion.hpp"
#include "dead_reckoning.hpp"
#include "feedback_confirmation.hpp"
#include "layout_config.hpp"
#include "train_poses.hpp"

using namespace covtrack;
using namespace covtrack::lenz;

namespace {

TrackLayout load(const std::string& relative) {
  auto layout = load_layout(std::string(COVTRACK_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(layout) << layout.error().message;
  return layout ? std::move(*layout) : TrackLayout{};
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const char* kTrain = R"(
[train]
max_speed_mps = 0.5
max_accel_mps2 = 0.5
[[train.vehicles]]
name = "loco"
length_m = 0.1
)";

std::string square_section(const std::string& name, const std::string& input, double side) {
  return "[[sections]]\nname = \"" + name + "\"\ninput = \"" + input +
         "\"\n[[sections.segments]]\nkind = \"straight\"\nlength_m = " + std::to_string(side) +
         "\n[[sections.segments]]\nkind = \"arc\"\nradius_m = 0.1\nangle_deg = 90\n";
}

}  // namespace

TEST(LenzLayout, TheSeedsTenSectionLoopLoadsAndCloses) {
  const TrackLayout layout = load("config/lenz_layout.toml");
  ASSERT_EQ(layout.sections().size(), 10u);
  EXPECT_NEAR(layout.length_m(), 2 * 1.2 + 2 * std::numbers::pi * 0.45, 1e-9);
  EXPECT_EQ(layout.train().vehicles.size(), 4u);
  EXPECT_EQ(layout.sections()[8].input.module, 66);
  EXPECT_EQ(layout.sections()[8].input.input, 1);
  // The pose is continuous around the whole loop, also across the origin.
  for (double s = 0; s < layout.length_m() + 0.01; s += 0.005) {
    const Pose a = layout.pose_at(s), b = layout.pose_at(s + 0.001);
    ASSERT_NEAR((a.translation() - b.translation()).norm(), 0.001, 1e-5) << "at s = " << s;
    ASSERT_LT(se3_log(a.inverse() * b).tail<3>().norm(), 0.001 / 0.45 + 1e-6) << "at s = " << s;
    ASSERT_NEAR((a.linear().transpose() * a.linear() - Mat3::Identity()).norm(), 0, 1e-12);
  }
  // On the arcs the body turns about its z axis at 1/radius per metre; on straights not at all.
  EXPECT_NEAR(layout.body_rate(0.3)(5), 0.0, 1e-6);
  EXPECT_NEAR(layout.body_rate(1.2 + 0.2)(5), 1 / 0.45, 1e-4);
  EXPECT_NEAR(layout.body_rate(1.2 + 0.2)(0), 1.0, 1e-4);
}

TEST(LenzLayout, ALoopThatDoesNotCloseIsRejected) {
  std::string text = kTrain;
  for (int i = 0; i < 3; ++i) text += square_section("q" + std::to_string(i), "65:" + std::to_string(i + 1), 0.3);
  const auto path = write_temp("open_loop.toml", text);
  const auto layout = load_layout(path);
  ASSERT_FALSE(layout);
  EXPECT_NE(layout.error().message.find("does not close"), std::string::npos) << layout.error().message;
  // Four of them close.
  text += square_section("q3", "65:4", 0.3);
  EXPECT_TRUE(load_layout(write_temp("closed_loop.toml", text)));
}

TEST(LenzLayout, BadInputsAreReportedWithFileAndLine) {
  std::string text = kTrain;
  text += square_section("a", "65:1", 0.3) + square_section("b", "65:9", 0.3) + square_section("c", "x", 0.3) +
          square_section("d", "65:1", 0.3);
  const auto path = write_temp("bad_inputs.toml", text);
  const auto layout = load_layout(path);
  ASSERT_FALSE(layout);
  const std::string& m = layout.error().message;
  EXPECT_NE(m.find("'65:9' is not \"module:input\""), std::string::npos) << m;
  EXPECT_NE(m.find("'x' is not"), std::string::npos) << m;
  EXPECT_NE(m.find("65:1 watches another section"), std::string::npos) << m;
  EXPECT_NE(m.find(path + ":"), std::string::npos) << m;
}

namespace {

struct HonestyFigures {
  int samples = 0, inside = 0, thesis_inside = 0, pose_inside = 0;
  double width_sum = 0, error_sum = 0;
  std::size_t inconsistencies = 0;
};

// A reader held up now and then (a stalled daemon): every `every`-th crossing is read
// `hold_s` later still, and the reckoner is told so or not.
struct HeldUpReader {
  int every = 0;  // 0: never held up
  double hold_s = 0;
  bool told = true;
};

// Runs the train of the short test layout with the given profile for `seconds` of
// simulated time; occupancy changes reach the estimator `latency` late (uniform in
// [0, max]), plus a held-up reader's hold.
HonestyFigures run_simulated(const TrackLayout& layout, const std::vector<SpeedStep>& profile, double seconds,
                             HeldUpReader held_up = {}) {
  const DeadReckoningParams params{0.05};
  DeadReckoner reckoner(layout, params);
  const TrainMotion motion(profile, 0.8 * layout.train().max_accel_mps2, 0.1);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> latency(0, params.crossing_latency_s);
  const PoseModelParams pose_params;

  struct Delivery { double t; std::size_t section; double read_late_s; };
  std::deque<Delivery> pending;
  int crossings = 0;
  double held_until = -1;  // a held-up reader publishes nothing until it runs again
  std::size_t section = layout.section_at(motion.s_at(0));
  auto occupancy_of = [&](std::size_t sec) {
    std::vector<bool> occ(layout.sections().size(), false);
    occ[sec] = true;
    return std::optional<std::vector<bool>>(occ);
  };
  reckoner.on_occupancy(occupancy_of(section), 0);
  // The dissertation's estimator (section 7.3), for comparison:
  // s = s0 + v t, +- (v_max - v) t.
  double thesis_entry_t = -1, thesis_v = 0, thesis_s0 = 0, thesis_prev_entry = -1;

  HonestyFigures f;
  const double dt = 0.001;
  for (int i = 1; i * dt < seconds; ++i) {
    const double t = i * dt;
    const double s_true = motion.s_at(t);
    const std::size_t now_in = layout.section_at(s_true);
    if (now_in != section) {
      section = now_in;
      const bool held = held_up.every > 0 && ++crossings % held_up.every == 0;
      const double hold_s = held ? held_up.hold_s : 0.0;
      // A later crossing cannot be read before this one.
      const double read_at = std::max(t + latency(rng) + hold_s, pending.empty() ? 0.0 : pending.back().t);
      pending.push_back({read_at, now_in, held && held_up.told ? hold_s : 0.0});
      if (held) held_until = read_at;
    }
    while (!pending.empty() && pending.front().t <= t) {
      const Delivery d = pending.front();
      reckoner.on_occupancy(occupancy_of(d.section), d.t, d.read_late_s);
      if (thesis_prev_entry >= 0)
        thesis_v = layout.sections()[layout.previous(d.section)].length_m / (d.t - thesis_prev_entry);
      thesis_prev_entry = d.t;
      thesis_entry_t = d.t;
      thesis_s0 = layout.sections()[d.section].start_s;
      pending.pop_front();
    }
    if (i % 10 != 0 || t < held_until) continue;
    const AlongTrack est = reckoner.estimate(t);
    if (est.state != AlongTrack::State::DeadReckoning) continue;
    ++f.samples;
    const double offset = layout.wrap(s_true - est.lo_s);
    f.inside += offset <= est.hi_s - est.lo_s + 1e-12;
    f.width_sum += est.hi_s - est.lo_s;
    f.error_sum += std::abs(layout.wrap(s_true - est.mid_s() + layout.length_m() / 2) - layout.length_m() / 2);
    if (thesis_entry_t >= 0) {
      const double tau = t - thesis_entry_t;
      const double centre = thesis_s0 + thesis_v * tau, half = (layout.train().max_speed_mps - thesis_v) * tau;
      const double d = std::abs(layout.wrap(s_true - centre + layout.length_m() / 2) - layout.length_m() / 2);
      f.thesis_inside += d <= half;
    }
    // The 6-D pose: locomotive's true pose inside the reported 99% ellipsoid (chi-square, 6 dof).
    const double sigma = along_track_sigma(est, pose_params);
    const Mat6 cov = vehicle_covariance(layout, est.mid_s(), sigma, pose_params);
    const Vec6 e = boxminus(layout.pose_at(s_true), layout.pose_at(est.mid_s()));
    f.pose_inside += e.dot(cov.ldlt().solve(e)) <= 16.812;
  }
  f.inconsistencies = reckoner.inconsistencies();
  return f;
}

}  // namespace

TEST(LenzDeadReckoning, ContainsTheTruthThroughSpeedChangesAndStops) {
  const TrackLayout layout = load("tests/data/lenz_short_layout.toml");
  // Accelerate, cruise, slow down, cruise, stop, wait, restart: over many laps.
  const std::vector<SpeedStep> profile{{0.5, 2}, {0.15, 1.5}, {0, 1}, {0.4, 1.5}, {0.05, 2}, {0, 0.5}};
  const HonestyFigures f = run_simulated(layout, profile, 120);
  ASSERT_GT(f.samples, 5000);
  const double inside = double(f.inside) / f.samples;
  const double thesis_inside = double(f.thesis_inside) / f.samples;
  const double pose_inside = double(f.pose_inside) / f.samples;
  const double mean_width = f.width_sum / f.samples, mean_error = f.error_sum / f.samples;
  std::printf("along-track 99%% interval holds the truth %.4f of %d samples (dissertation's rule: %.4f); "
              "6-D 99%% ellipsoid: %.4f; mean interval width %.4f m, mean |error| %.4f m (ratio %.2f)\n",
              inside, f.samples, thesis_inside, pose_inside, mean_width, mean_error, mean_width / mean_error);
  EXPECT_GE(inside, 0.99);
  EXPECT_GE(pose_inside, 0.99);
  // The dissertation's rule misses a train that slows down or stops.
  EXPECT_LT(thesis_inside, inside);
  // Not absurdly wide: a uniform spread over the interval would give width / error = 4.
  EXPECT_LT(mean_width / mean_error, 8.0);
  // And narrower than "somewhere in the occupied section", the estimate without dead reckoning.
  const double mean_section_m = layout.length_m() / layout.sections().size();
  std::printf("mean interval width / mean section length: %.3f\n", mean_width / mean_section_m);
  EXPECT_LT(mean_width, mean_section_m);
}

namespace {

// The short layout with reversible = true.
Result<TrackLayout> reversible_short_layout() {
  std::ifstream in(std::string(COVTRACK_SOURCE_DIR) + "/tests/data/lenz_short_layout.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("[train]\n"), 8, "[train]\nreversible = true\n");
  return load_layout(write_temp("reversible.toml", text));
}

// Backs up a little each lap.
const std::vector<SpeedStep> kBackingUpProfile{{0.4, 1}, {0, 0.5}, {-0.3, 0.8}, {0, 0.3}, {0.5, 1.5}, {0.1, 1}, {0, 0.5}};

}  // namespace

TEST(LenzDeadReckoning, AReversibleTrainThatBacksUpIsStillContained) {
  auto loaded = reversible_short_layout();
  ASSERT_TRUE(loaded) << loaded.error().message;
  const HonestyFigures f = run_simulated(*loaded, kBackingUpProfile, 120);
  ASSERT_GT(f.samples, 5000);
  const double inside = double(f.inside) / f.samples;
  std::printf("reversible: along-track 99%% interval holds the truth %.4f of %d samples; 6-D %.4f; "
              "mean width %.4f m, mean |error| %.4f m\n",
              inside, f.samples, double(f.pose_inside) / f.samples, f.width_sum / f.samples, f.error_sum / f.samples);
  EXPECT_GE(inside, 0.99);
  EXPECT_EQ(f.inconsistencies, 0u);
  // The same run on the forward-only layout: each backing-up is an inconsistency.
  const HonestyFigures forward_only = run_simulated(load("tests/data/lenz_short_layout.toml"), kBackingUpProfile, 30);
  EXPECT_GT(forward_only.inconsistencies, 0u);
}

TEST(LenzDeadReckoning, AReaderHeldUpIsAllowedForWhenItSaysHowLong) {
  // Every third crossing read 0.3 s late on top of the latency: the estimate holds the
  // truth when the reader passes on how long it was held up, and not when it does not.
  const TrackLayout layout = load("tests/data/lenz_short_layout.toml");
  const std::vector<SpeedStep> profile{{0.5, 2}, {0.15, 1.5}, {0, 1}, {0.4, 1.5}, {0.05, 2}, {0, 0.5}};
  const HonestyFigures told = run_simulated(layout, profile, 120, {3, 0.3, true});
  const HonestyFigures untold = run_simulated(layout, profile, 120, {3, 0.3, false});
  ASSERT_GT(told.samples, 5000);
  const double told_inside = double(told.inside) / told.samples;
  const double untold_inside = double(untold.inside) / untold.samples;
  std::printf("held up 0.3 s every third crossing: inside %.4f when told, %.4f when not; 6-D %.4f when told\n",
              told_inside, untold_inside, double(told.pose_inside) / told.samples);
  EXPECT_GE(told_inside, 0.99);
  EXPECT_GE(double(told.pose_inside) / told.samples, 0.99);
  EXPECT_LT(untold_inside, 0.97);
  // The same for a train that backs up: it may have reversed further during the hold.
  auto reversible = reversible_short_layout();
  ASSERT_TRUE(reversible) << reversible.error().message;
  const HonestyFigures backing = run_simulated(*reversible, kBackingUpProfile, 120, {3, 0.3, true});
  ASSERT_GT(backing.samples, 5000);
  std::printf("reversible, held up 0.3 s every third crossing: inside %.4f when told\n",
              double(backing.inside) / backing.samples);
  EXPECT_GE(double(backing.inside) / backing.samples, 0.99);
}

TEST(LenzDeadReckoning, FirstReportStopsAndLossAreHandled) {
  const TrackLayout layout = load("tests/data/lenz_short_layout.toml");
  DeadReckoner r(layout, {0.05});
  EXPECT_EQ(r.estimate(0).state, AlongTrack::State::Lost);
  std::vector<bool> occ(10, false);
  r.on_occupancy(std::nullopt, 0);  // inputs not all known yet
  EXPECT_EQ(r.estimate(0).state, AlongTrack::State::Lost);
  occ[3] = true;
  r.on_occupancy(occ, 1.0);
  AlongTrack a = r.estimate(1.5);
  EXPECT_EQ(a.state, AlongTrack::State::WholeSection);  // no crossing seen: anywhere in it
  EXPECT_DOUBLE_EQ(a.lo_s, layout.sections()[3].start_s);
  EXPECT_DOUBLE_EQ(a.hi_s, layout.sections()[3].end_s());
  occ[3] = false;
  occ[4] = true;
  r.on_occupancy(occ, 2.0);
  a = r.estimate(2.0);
  EXPECT_EQ(a.state, AlongTrack::State::DeadReckoning);
  EXPECT_EQ(a.section, 4u);
  EXPECT_NEAR(a.lo_s, layout.sections()[4].start_s, 1e-12);
  // First lap: speed unknown, so the far end grows at v_max and is clipped at the section
  // end plus what the train covers within the report latency.
  a = r.estimate(60.0);  // standing for a minute
  EXPECT_LE(a.hi_s, layout.sections()[4].end_s() + layout.train().max_speed_mps * 0.05 + 1e-12);
  // A reader that has not seen the port for 0.3 s (held up) allows for a crossing out of
  // the section that long unread.
  EXPECT_NEAR(r.estimate(60.0, 0.3).hi_s, layout.sections()[4].end_s() + layout.train().max_speed_mps * 0.35, 1e-12);
  EXPECT_NEAR(a.lo_s, layout.sections()[4].start_s, 1e-12);  // could have stopped at once
  // A jump to a section that does not follow: counted, and restarted from there.
  occ[4] = false;
  occ[7] = true;
  r.on_occupancy(occ, 61.0);
  EXPECT_EQ(r.inconsistencies(), 1u);
  EXPECT_EQ(r.estimate(61.0).state, AlongTrack::State::WholeSection);
  // Nothing occupied: LOST.
  occ[7] = false;
  r.on_occupancy(occ, 62.0);
  EXPECT_EQ(r.estimate(62.0).state, AlongTrack::State::Lost);
}

namespace {

// A feedback pair for one nibble of an RS-bus module (inputs as bits, input 1 or 5 first).
FeedbackPair nibble_pair(int module, bool upper, std::uint8_t bits) {
  return {static_cast<std::uint8_t>(module - 1), static_cast<std::uint8_t>(0x40 | (upper ? 0x10 : 0) | bits)};
}

}  // namespace

// The short layout: sections 0-7 are inputs 65:1-8, sections 8-9 are 66:1-2.
TEST(LenzFeedbackConfirmation, ImpossibleChangesAreHeldUntilAskedAgain) {
  const TrackLayout layout = load("tests/data/lenz_short_layout.toml");
  DeadReckoner r(layout, {0.05});
  FeedbackConfirmation fc(layout, 1.0);
  const auto step = [&](const Feedback& fb, double t) {
    auto o = fc.apply(fb, r, t);
    if (o.changed) r.on_occupancy(section_occupancy(layout, fc.state()), t);
    return o;
  };
  // Startup answers: section 0 occupied. Nothing to protect yet: applied at once.
  auto o = step({{nibble_pair(65, false, 0b0001), nibble_pair(65, true, 0), nibble_pair(66, false, 0),
                  nibble_pair(66, true, 0)}}, 0.0);
  EXPECT_TRUE(o.changed);
  EXPECT_TRUE(o.ask.empty());
  EXPECT_EQ(r.estimate(0.0).section, 0u);
  // Crossing ahead into section 1: applied at once.
  o = step({{nibble_pair(65, false, 0b0010)}}, 1.0);
  EXPECT_TRUE(o.changed);
  EXPECT_TRUE(o.ask.empty());
  EXPECT_EQ(r.estimate(1.0).section, 1u);
  EXPECT_EQ(r.estimate(1.0).state, AlongTrack::State::DeadReckoning);
  // A forged report: section 6 (65:7) occupied, section 1 clear. Held and asked for.
  o = step({{nibble_pair(65, true, 0b0100), nibble_pair(65, false, 0)}}, 1.2);
  EXPECT_FALSE(o.changed);
  ASSERT_EQ(o.ask.size(), 2u);
  EXPECT_EQ(o.ask[0].address, 64);
  EXPECT_EQ(fc.held(), 2u);
  EXPECT_EQ(r.estimate(1.2).section, 1u);
  EXPECT_EQ(r.inconsistencies(), 0u);
  // The answers repeat the true inputs: both dropped as noise, nothing changed.
  o = step({{nibble_pair(65, false, 0b0010)}}, 1.21);
  EXPECT_FALSE(o.changed);
  EXPECT_EQ(o.dropped.size(), 1u);
  o = step({{nibble_pair(65, true, 0)}}, 1.22);
  EXPECT_EQ(o.dropped.size(), 1u);
  EXPECT_NE(o.dropped[0].find("feedback module 65 inputs 5-8"), std::string::npos) << o.dropped[0];
  EXPECT_EQ(fc.held(), 0u);
  EXPECT_EQ(r.estimate(1.3).state, AlongTrack::State::DeadReckoning);
  // A true jump (a crossing was missed): confirmed by the answer, then believed.
  o = step({{nibble_pair(65, false, 0b1000)}}, 2.0);  // section 3 alone
  EXPECT_FALSE(o.changed);
  EXPECT_EQ(o.ask.size(), 1u);
  o = step({{nibble_pair(65, false, 0b1000)}}, 2.03);
  EXPECT_TRUE(o.changed);
  EXPECT_EQ(r.estimate(2.03).section, 3u);
  EXPECT_EQ(r.estimate(2.03).state, AlongTrack::State::WholeSection);
  EXPECT_EQ(r.inconsistencies(), 1u);
  // A vanished train is held too; unanswered, it is dropped after the timeout.
  o = step({{nibble_pair(65, false, 0)}}, 3.0);
  EXPECT_EQ(o.ask.size(), 1u);
  EXPECT_TRUE(fc.expire(3.5).dropped.empty());
  o = fc.expire(4.01);
  ASSERT_EQ(o.dropped.size(), 1u);
  EXPECT_NE(o.dropped[0].find("within 1.0 s"), std::string::npos) << o.dropped[0];
  EXPECT_EQ(r.estimate(4.01).section, 3u);
}

TEST(LenzPoseModel, LostIsInfiniteAndDegradedIsAValidCovariance) {
  const TrackLayout layout = load("config/lenz_layout.toml");
  std::vector<Pose> last;
  AlongTrack along;
  along.state = AlongTrack::State::DeadReckoning;
  along.section = 3;
  along.lo_s = layout.sections()[3].start_s;
  along.hi_s = along.lo_s + 0.2;
  const auto poses = train_poses(layout, along, {}, "table", 1, last);
  ASSERT_EQ(poses.size(), 4u);
  for (const auto& p : poses) {
    EXPECT_EQ(p.status, TrackingStatus::Degraded);
    Eigen::SelfAdjointEigenSolver<Mat6> eig(p.covariance);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0) << p.sensor;
    EXPECT_TRUE(p.covariance.allFinite());
    // Along the track (body x) the 99% half-width is the interval's half-width (0.1 m).
    EXPECT_NEAR(kZ99 * std::sqrt(p.covariance(0, 0)), 0.1, 0.01) << p.sensor;
  }
  // The cars trail the locomotive by their lengths and gaps.
  EXPECT_NEAR((poses[0].T_parent_child.translation() - poses[1].T_parent_child.translation()).norm(),
              0.1 + 0.01 + 0.075, 0.01);
  const auto lost = train_poses(layout, AlongTrack{}, {}, "table", 2, last);
  for (std::size_t k = 0; k < lost.size(); ++k) {
    EXPECT_EQ(lost[k].status, TrackingStatus::Lost);
    test::expect_lost_covariance(lost[k].covariance);
    EXPECT_TRUE(lost[k].T_parent_child.isApprox(poses[k].T_parent_child));  // the last estimate
  }
}

namespace {

// Reads [devices.train] of `text` (as if from config/<name>) with the lenz driver's reader.
std::pair<LenzConfig, ConfigErrors> read_device(const std::string& text) {
  const std::string file = std::string(COVTRACK_SOURCE_DIR) + "/config/test_lenz.toml";
  auto root = parse_toml(text, file);
  EXPECT_TRUE(root) << root.error().message;
  ConfigErrors errors;
  const toml::table* device = (*root)["devices"]["train"].as_table();
  TableReader r(*device, "devices.train", lenz_device_spec(), file, errors);
  LenzConfig config = read_lenz_config(r, "train");
  return {config, errors};
}

}  // namespace

TEST(LenzConfig, TheExampleReadsAndTheLayoutPathIsRelativeToTheConfig) {
  const auto [config, errors] = read_device(
      "[devices.train]\ntype = \"lenz\"\nport = \"/dev/ttyUSB0\"\nlayout = \"lenz_layout.toml\"\n");
  EXPECT_TRUE(errors.empty()) << errors.joined();
  ASSERT_TRUE(config.layout);
  EXPECT_EQ(config.layout->sections().size(), 10u);
  EXPECT_EQ(config.baud, 19200);
  EXPECT_TRUE(config.rts_cts);
  const auto [usb, usb_errors] = read_device(
      "[devices.train]\ntype = \"lenz\"\nport = \"/dev/ttyUSB0\"\ninterface = \"liusb\"\nlayout = \"lenz_layout.toml\"\n");
  EXPECT_TRUE(usb_errors.empty()) << usb_errors.joined();
  EXPECT_EQ(usb.baud, 57600);
}

TEST(LenzConfig, BadValuesAreReportedTogether) {
  const auto [config, errors] = read_device(
      "[devices.train]\ntype = \"lenz\"\ninterface = \"liusb\"\nbaud = 19200\nlayout = \"missing.toml\"\n"
      "keepalive_s = 2\nlink_timeout_s = 1\nrate_hz = nan\n");
  const std::string all = errors.joined();
  EXPECT_NE(all.find("devices.train.port"), std::string::npos) << all;  // required
  EXPECT_NE(all.find("LI-USB runs at 57600"), std::string::npos) << all;
  EXPECT_NE(all.find("missing.toml: cannot read the file"), std::string::npos) << all;
  EXPECT_NE(all.find("must be longer than keepalive_s"), std::string::npos) << all;
  EXPECT_NE(all.find("devices.train.rate_hz"), std::string::npos) << all;  // not a finite number
  EXPECT_NE(all.find("test_lenz.toml:"), std::string::npos) << all;
}
