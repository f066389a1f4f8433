#include "covtrack/devices/lenz/lenz_driver.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "covtrack/devices/serial/serial_port.hpp"
#include "covtrack/devices/valid_frame_watchdog.hpp"
#include "feedback_confirmation.hpp"
#include "overloaded.hpp"
#include "train_poses.hpp"
#include "xpressnet_framing.hpp"
#include "xpressnet_messages.hpp"

namespace covtrack::lenz {
namespace {

using Clock = DriverClock;
using std::chrono::duration;
using std::chrono::duration_cast;
using std::chrono::milliseconds;

// A held feedback change (feedback_confirmation.hpp) is asked for again at once; an
// interface answers within tens of milliseconds, so one not confirmed in this long is
// dropped.
constexpr double kConfirmTimeout_s = 1.0;

// The reader looks at the port at least this often (it waits for bytes no longer).
constexpr milliseconds kLongestWait{20};
// Time this long beyond the reader's waits means it was held up (the daemon stalled, the
// machine was swapping): bytes read then may have waited all of it.
constexpr milliseconds kHeldUp = kLongestWait;

// One read of the port: when it began (asked how long to wait) and how long it would wait.
struct Look {
  Clock::time_point from;
  Clock::duration wait;
};

// How long bytes read at `now` by `current` may have waited unread, when the reader was
// held up; 0 when not. They came after `previous` last saw the port, at some moment after
// it began: an empty read may have looked just before a hold-up that caught it on its
// way back, so its end says nothing. Normally the two reads' waits account for the span.
double unread_for_s(const Look& previous, const Look& current, Clock::time_point now) {
  const auto unseen = now - previous.from;
  const auto waited = std::min(current.from - previous.from, previous.wait) + std::min(now - current.from, current.wait);
  return unseen - waited >= kHeldUp ? duration<double>(unseen).count() : 0.0;
}

// How long the port has gone unseen at `now`, when the reader was held up after `current`
// began (0 when not): what a read at `now` would find may have waited that long.
double unseen_for_s(const Look& current, Clock::time_point now) {
  return unread_for_s(current, Look{now, Clock::duration::zero()}, now);
}

Clock::duration seconds(double s) { return duration_cast<Clock::duration>(duration<double>(s)); }

// Bytes as read: when the read returned them (what a report in them is timed by, however
// long the driver then takes to act on it: a crossing must not seem later than it was)
// and how long they may have waited unread before (unread_for_s).
struct Read {
  double at_s = 0;
  double late_s = 0;
};

class LenzDriver final : public Driver {
 public:
  LenzDriver(const LenzConfig& config, DriverClock& clock)
      : config_(config),
        clock_(clock),
        reckoner_(*config.layout, config.reckoning),
        feedback_(*config.layout, kConfirmTimeout_s),
        period_(seconds(1.0 / config.rate_hz)) {}

  Result<void> run(SampleSink& sink, std::stop_token stop) override {
    bool connected_before = false;
    next_sample_ = clock_.now();
    while (!stop.stop_requested()) {
      auto port = serial::SerialPort::open({config_.port, config_.baud, config_.rts_cts});
      if (!port) {
        if (!connected_before) return std::unexpected(port.error());
        sink.count_error(port.error().message);
        publish_lost_for(sink, stop, seconds(config_.reconnect_s));
        continue;
      }
      connected_before = true;
      if (auto ended = session(**port, sink, stop); !ended) {
        if (device_failed_) {
          publish(sink, AlongTrack{});  // what the vehicles are while the daemon resets the device
          return std::unexpected(*device_failed_);
        }
        sink.count_error(ended.error().message);
      }
      // Crossings may be missed while the link is down: start the estimate afresh.
      reckoner_.reset();
      feedback_.reset();
      to_ask_.clear();
      decoder_.reset();
    }
    return {};
  }

 private:
  // Talks to one open port until stop (success) or until the link fails (the error).
  // Only a line that keeps delivering bytes without one status reply ends the whole
  // run (the device has FAILED, the daemon resets it); a silent one is reopened here.
  Result<void> session(serial::SerialPort& port, SampleSink& sink, std::stop_token stop) {
    if (auto sent = send_startup(port, sink); !sent) return sent;
    auto last_rx = clock_.now();
    auto next_keepalive = clock_.now() + seconds(config_.keepalive_s);
    // A status reply is the sign of life: the interface answers every keepalive with one,
    // and its three checked bytes (62 22 .. XOR) turn up in noise about once in 16
    // million bytes, where a frame with a valid XOR byte turns up once in 256.
    ValidFrameWatchdog watchdog(config_.no_valid_frames_s, clock_.now());
    std::uint64_t bytes_since_reply = 0;
    const std::uint64_t bad_frames_at_start = decoder_.counters().bad_frames;
    std::vector<std::uint8_t> buffer;
    Look previous{clock_.now(), Clock::duration::zero()};
    while (!stop.stop_requested()) {
      // All that waits, in one read: after a hold-up every byte of the backlog may have
      // waited that long, not only the first read's worth.
      buffer.clear();
      const Look current{clock_.now(), clock_.io_timeout(stop, next_sample_, kLongestWait)};  // in this order
      auto got = port.read_waiting(buffer, duration_cast<milliseconds>(current.wait));
      if (!got) return std::unexpected(got.error());
      const auto now = clock_.now();
      // Normally the read wakes as the bytes come, and the configured latency covers the
      // rest; after a hold-up a crossing may have waited the whole time, and the estimate
      // must allow for that.
      const double read_late_s = unread_for_s(previous, current, now);
      previous = current;
      if (*got > 0) {
        last_rx = now;
        bytes_since_reply += *got;
        sink.raw(ByteDirection::FromDevice, buffer.data(), buffer.size());
        if (handle_bytes(buffer, Read{Clock::seconds_of(now), read_late_s}, sink)) {
          watchdog.valid_frame(now);
          bytes_since_reply = 0;
        }
      }
      const double now_s = Clock::seconds_of(now);
      take(feedback_.expire(now_s), Read{now_s, 0.0}, sink);  // drops only: changes nothing
      if (auto sent = ask_held(port, sink); !sent) return sent;
      if (now - last_rx > seconds(config_.link_timeout_s))
        return fail(fmt::format("serial port {}: interface silent for {:.1f} s (no reply to the status request)",
                                config_.port, duration<double>(now - last_rx).count()));
      if (auto expired = watchdog.expired(now)) {
        device_failed_ = Error{fmt::format(
            "serial port {}: {} (no answer to the status request in {} bytes; {} bad frames this "
            "connection); the interface will be reset",
            config_.port, *expired, bytes_since_reply, decoder_.counters().bad_frames - bad_frames_at_start)};
        return std::unexpected(*device_failed_);
      }
      if (now >= next_keepalive) {
        if (auto sent = send(port, sink, CommandStationStatusRequest{}); !sent) return sent;
        next_keepalive = now + seconds(config_.keepalive_s);
      }
      // Timed now, not at the read: the work above may have been held up, and the port
      // has gone unseen for that long too.
      const auto publish_at = clock_.now();
      if (publish_at >= next_sample_)
        publish(sink, reckoner_.estimate(Clock::seconds_of(publish_at), unseen_for_s(current, publish_at)));
    }
    return {};
  }

  Result<void> send_startup(serial::SerialPort& port, SampleSink& sink) {
    std::vector<Request> requests = {InterfaceVersionRequest{}, CommandStationVersionRequest{},
                                     CommandStationStatusRequest{}};
    std::set<int> modules;
    for (const auto& s : config_.layout->sections()) modules.insert(s.input.module);
    for (int m : modules) {
      requests.push_back(FeedbackRequest{static_cast<std::uint8_t>(m - 1), false});
      requests.push_back(FeedbackRequest{static_cast<std::uint8_t>(m - 1), true});
    }
    for (const auto& r : requests)
      if (auto sent = send(port, sink, r); !sent) return sent;
    return {};
  }

  Result<void> send(serial::SerialPort& port, SampleSink& sink, const Request& request) {
    const Prefix prefix = config_.interface == Interface::LiUsb ? Prefix::Reply : Prefix::None;  // FF FE
    const auto bytes = encode_frame(request_bytes(request), prefix);
    sink.raw(ByteDirection::ToDevice, bytes.data(), bytes.size());
    // A few bytes take milliseconds even at 19200 baud; a longer wait means the interface
    // holds CTS, and waiting on would delay noticing a stop request.
    return port.write_all(bytes, milliseconds(80));
  }

  // Acts on what the feedback reports did: re-runs the reckoner on a change, counts
  // changes dropped as noise, and keeps the nibbles to ask for again (sent by ask_held).
  void take(const FeedbackConfirmation::Outcome& outcome, const Read& read, SampleSink& sink) {
    if (outcome.changed)
      reckoner_.on_occupancy(section_occupancy(*config_.layout, feedback_.state()), read.at_s, read.late_s);
    for (const auto& line : outcome.dropped) sink.count_error(fmt::format("{}: {}", config_.port, line));
    to_ask_.insert(to_ask_.end(), outcome.ask.begin(), outcome.ask.end());
  }

  Result<void> ask_held(serial::SerialPort& port, SampleSink& sink) {
    for (const auto& request : std::exchange(to_ask_, {}))
      if (auto sent = send(port, sink, request); !sent) return sent;
    return {};
  }

  // Returns whether a status reply came (the sign of life; see session()).
  bool handle_bytes(std::span<const std::uint8_t> bytes, const Read& read, SampleSink& sink) {
    bool status_reply = false;
    const FramingCounters before = decoder_.counters();
    const auto frames = decoder_.push(bytes);
    const FramingCounters& after = decoder_.counters();
    for (auto i = before.bad_frames; i < after.bad_frames; ++i) {
      sink.count_error(fmt::format("{}: bytes that are not a frame skipped (bad XOR byte or stray header)", config_.port));
      sink.count_resync();
    }
    for (const auto& frame : frames) {
      std::visit(overloaded{
                     [&](const Feedback& fb) {
                       take(feedback_.apply(fb, reckoner_, read.at_s), read, sink);
                     },
                     [&](const InterfaceNotice& n) {
                       if (n.code != 0x04 && n.code != 0x07) sink.count_error(describe_notice(n.code));
                     },
                     [&](const CommandStationStatus&) { status_reply = true; },
                     [&](const auto&) {},
                 },
                 interpret_reply(frame));
    }
    return status_reply;
  }

  void publish(SampleSink& sink, const AlongTrack& along) {
    for (const auto& p : train_poses(*config_.layout, along, config_.pose_model, config_.parent_frame, clock_.now_us(), last_))
      sink.pose(p);
    next_sample_ += period_;
    if (next_sample_ < clock_.now()) next_sample_ = clock_.now() + period_;  // fell behind: no burst
  }

  void publish_lost_for(SampleSink& sink, std::stop_token stop, Clock::duration how_long) {
    const auto end = clock_.now() + how_long;
    while (clock_.now() < end) {
      if (!clock_.sleep_until(stop, std::min(end, next_sample_))) return;
      if (clock_.now() >= next_sample_) publish(sink, AlongTrack{});
    }
  }

  LenzConfig config_;
  DriverClock& clock_;
  DeadReckoner reckoner_;
  FeedbackConfirmation feedback_;
  std::vector<FeedbackRequest> to_ask_;
  FrameDecoder decoder_;
  Clock::duration period_;
  Clock::time_point next_sample_;
  std::vector<Pose> last_;
  std::optional<Error> device_failed_;  // set by a session that ends the whole run (no valid frames)
};

}  // namespace

std::unique_ptr<Driver> make_lenz_driver(const LenzConfig& config, DriverClock& clock) {
  return std::make_unique<LenzDriver>(config, clock);
}

}  // namespace covtrack::lenz
