#include "covtrack/emulators/lenz/lenz_emulator.hpp"

#include <algorithm>
#include <chrono>

#include "overloaded.hpp"

namespace covtrack::lenz {
namespace {

constexpr std::size_t kMaxPairsPerMessage = 7;  // header nibble 14 data bytes

}  // namespace

Result<std::unique_ptr<LenzEmulator>> LenzEmulator::create(LenzEmulatorOptions options, DriverClock& clock) {
  if (!options.layout) return fail("lenz emulator: no layout");
  if (options.accel_mps2 <= 0) options.accel_mps2 = 0.8 * options.layout->train().max_accel_mps2;
  const Train& train = options.layout->train();
  for (auto& step : options.profile) {
    if (step.speed_mps < 0 && !train.reversible)
      return fail("lenz emulator: the profile runs backwards but the layout's train is not reversible");
    step.speed_mps = std::clamp(step.speed_mps, -train.max_speed_mps, train.max_speed_mps);
  }
  auto pty = serial::PseudoTerminal::create(options.link_path);
  if (!pty) return std::unexpected(pty.error());
  return std::unique_ptr<LenzEmulator>(new LenzEmulator(std::move(options), std::move(*pty), clock));
}

LenzEmulator::LenzEmulator(LenzEmulatorOptions options, serial::PseudoTerminal pty, DriverClock& clock)
    : options_(std::move(options)),
      clock_(clock),
      pty_(std::move(pty)),
      motion_(options_.profile, options_.accel_mps2, options_.start_s),
      start_us_(clock.now_us()) {
  for (const auto& s : options_.layout->sections()) module_inputs_[s.input.module] = 0;
  occupied_section_ = options_.layout->section_at(options_.start_s);
  const auto& in = options_.layout->sections()[occupied_section_].input;
  module_inputs_[in.module] |= static_cast<std::uint8_t>(1u << (in.input - 1));
}

double LenzEmulator::true_s_at(std::int64_t time_us) const {
  return motion_.s_at(static_cast<double>(time_us - start_us_) * 1e-6);
}

std::uint8_t LenzEmulator::nibble(int module, bool upper) const {
  const std::uint8_t inputs = module_inputs_.at(module);
  return static_cast<std::uint8_t>(0x40 | (upper ? 0x10 : 0) | ((upper ? inputs >> 4 : inputs) & 0x0F));
}

void LenzEmulator::send(const Reply& reply, Prefix prefix) {
  if (options_.interface == Interface::Li101f) prefix = Prefix::None;
  const auto bytes = encode_frame(reply_bytes(reply), prefix);
  (void)pty_.write(bytes);
}

void LenzEmulator::answer(const Frame& frame) {
  ++requests_answered_;
  std::visit(overloaded{
                 [&](const InterfaceVersionRequest&) { send(InterfaceVersion{0x01, 0x36}, Prefix::Reply); },
                 [&](const CommandStationVersionRequest&) { send(CommandStationVersion{0x36, 0x00}, Prefix::Reply); },
                 [&](const CommandStationStatusRequest&) {
                   send(CommandStationStatus{static_cast<std::uint8_t>(track_power_ ? 0x00 : kStatusEmergencyOff)},
                        Prefix::Reply);
                 },
                 [&](const FeedbackRequest& r) {
                   const int module = r.address + 1;
                   const std::uint8_t data = module_inputs_.count(module)
                                                 ? nibble(module, r.upper_nibble)
                                                 : static_cast<std::uint8_t>(0x40 | (r.upper_nibble ? 0x10 : 0));
                   send(Feedback{{{r.address, data}}}, Prefix::Reply);
                 },
                 [&](const InterfaceSettingRequest& r) {
                   // Addresses 32-255 only ask; baud code 1 = 19200 (factory default).
                   const std::uint8_t value = r.which == 1 ? (r.value < 32 ? r.value : 30) : 1;
                   send(InterfaceSetting{r.which, value}, Prefix::Reply);
                 },
                 [&](const TrackPowerRequest& r) {
                   track_power_ = r.on;
                   send(Broadcast{r.on ? BroadcastKind::TrackPowerOn : BroadcastKind::TrackPowerOff},
                        Prefix::Unsolicited);
                 },
                 [&](const EmergencyStopRequest&) { send(Broadcast{BroadcastKind::EmergencyStop}, Prefix::Unsolicited); },
                 [&](const UnknownRequest&) { send(Broadcast{BroadcastKind::NotSupported}, Prefix::Reply); },
             },
             interpret_request(frame));
}

void LenzEmulator::update_occupancy(double s) {
  const std::size_t section = options_.layout->section_at(s);
  if (section == occupied_section_) return;
  const std::map<int, std::uint8_t> before = module_inputs_;
  const auto& old_in = options_.layout->sections()[occupied_section_].input;
  const auto& new_in = options_.layout->sections()[section].input;
  module_inputs_[old_in.module] &= static_cast<std::uint8_t>(~(1u << (old_in.input - 1)));
  module_inputs_[new_in.module] |= static_cast<std::uint8_t>(1u << (new_in.input - 1));
  occupied_section_ = section;
  if (!pty_.plugged()) return;  // nobody to tell; a reconnecting driver asks anyway
  // Every changed nibble, in one broadcast (the command station batches them).
  Feedback fb;
  for (const auto& [module, inputs] : module_inputs_) {
    const std::uint8_t changed = inputs ^ before.at(module);
    const auto address = static_cast<std::uint8_t>(module - 1);
    if (changed & 0x0F) fb.pairs.push_back({address, nibble(module, false)});
    if (changed & 0xF0) fb.pairs.push_back({address, nibble(module, true)});
  }
  for (std::size_t i = 0; i < fb.pairs.size(); i += kMaxPairsPerMessage) {
    Feedback part;
    part.pairs.assign(fb.pairs.begin() + static_cast<std::ptrdiff_t>(i),
                      fb.pairs.begin() + static_cast<std::ptrdiff_t>(std::min(fb.pairs.size(), i + kMaxPairsPerMessage)));
    send(part, Prefix::Unsolicited);
    ++broadcasts_sent_;
  }
}

void LenzEmulator::forge_feedback(const FeedbackPair& pair) {
  std::lock_guard lock(forged_mutex_);
  forged_.push_back(pair);
}

void LenzEmulator::publish_truth(const std::function<void(const TruthSample&)>& truth, std::int64_t time_us,
                                 double s) {
  const auto& train = options_.layout->train();
  for (std::size_t k = 0; k < train.vehicles.size(); ++k) {
    const auto& name = train.vehicles[k].name;
    truth({name, options_.parent_frame, name, time_us, options_.layout->pose_at(s - train.offset_behind_m(k))});
  }
}

void LenzEmulator::run(std::stop_token stop, const std::function<void(const TruthSample&)>& truth) {
  using namespace std::chrono;
  const auto tick = milliseconds(std::max<std::int64_t>(1, std::llround(options_.tick_s * 1000)));
  const std::int64_t truth_period_us = std::llround(1e6 / options_.truth_hz);
  std::int64_t next_truth_us = clock_.now_us();
  auto next_tick = clock_.now();
  std::uint8_t buffer[256];
  while (!stop.stop_requested()) {
    if (want_plugged_ != pty_.plugged()) {
      if (want_plugged_) {
        if (pty_.replug()) decoder_.reset();
      } else {
        pty_.unplug();
      }
    }
    if (pty_.plugged()) {
      auto got = pty_.read_some(buffer, clock_.io_timeout(stop, next_tick, tick));
      if (got && *got > 0)
        for (const auto& frame : decoder_.push({buffer, *got})) answer(frame);
    } else if (!clock_.sleep_until(stop, next_tick)) {
      break;
    }
    next_tick = clock_.now() + tick;
    std::vector<FeedbackPair> forged;
    {
      std::lock_guard lock(forged_mutex_);
      forged.swap(forged_);
    }
    for (const auto& pair : forged)
      if (pty_.plugged()) send(Feedback{{pair}}, Prefix::Unsolicited);
    const std::int64_t t_us = clock_.now_us();
    const double s = true_s_at(t_us);
    update_occupancy(s);
    if (truth && t_us >= next_truth_us) {
      publish_truth(truth, t_us, s);
      next_truth_us = std::max(next_truth_us + truth_period_us, t_us - truth_period_us);
    }
  }
}

}  // namespace covtrack::lenz
