#include "covtrack/devices/vrpn/vrpn_driver.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/socket.hpp"
#include "covtrack/vrpn/tracker_report.hpp"

namespace covtrack::vrpn {
namespace {

using Clock = DriverClock;
constexpr auto kPingPeriod = std::chrono::seconds(1);  // as often as a VRPN client pings
constexpr std::chrono::milliseconds kPoll(20);          // a stop is noticed within this
// A VRPN time stamp further than this from our clock comes from an unsynchronised host:
// the arrival time is used instead.
constexpr std::int64_t kMaxClockOffset_us = 1'000'000;
constexpr double kSendTimeout_s = 1.0;

struct SensorState {
  std::string name;
  Mat6 covariance = Mat6::Zero();
  Pose last = Pose::Identity();
  Clock::time_point last_report{};
  bool reported = false;  // has published a pose that is not LOST
};

class VrpnDriver final : public Driver {
 public:
  VrpnDriver(VrpnConfig config, DriverClock& clock) : config_(std::move(config)), clock_(clock) {
    for (const auto& s : config_.sensors) sensors_[s.number] = SensorState{s.name, s.covariance};
  }

  Result<void> run(SampleSink& sink, std::stop_token stop) override {
    const std::string where = "VRPN tracker " + config_.tracker.text();
    auto host = resolve_ipv4(config_.tracker.host, config_.connect_timeout_s, stop);
    if (stop.stop_requested()) return {};
    if (!host) return fail(fmt::format("{}: {}", where, host.error().message));
    auto socket = connect_tcp(ipv4_address(*host, config_.tracker.port), config_.connect_timeout_s, stop);
    if (stop.stop_requested()) return {};
    if (!socket)
      return fail(fmt::format("{}: {} (is a vrpn_server running there?)", where, socket.error().message));
    auto result = stream(*socket, sink, stop);
    if (!result) {
      report_lost(sink);
      return fail(fmt::format("{}: {} (sensors reported LOST)", where, result.error().message));
    }
    return {};
  }

 private:
  Result<void> stream(const Socket& socket, SampleSink& sink, std::stop_token stop) {
    const std::string& device = config_.tracker.name;
    Session session({device}, {std::string(kTrackerPosQuat), std::string(kPing), std::string(kPong)});
    const auto connected = clock_.now();
    auto last_heard = connected, last_ping = Clock::time_point{};
    bool answered = false, announced = false;
    std::array<std::uint8_t, 8192> buffer{};
    while (!stop.stop_requested()) {
      if (session.has_output())
        if (auto sent = send_all(socket, session.take_output(), kSendTimeout_s); !sent)
          return fail("the connection broke: " + sent.error().message);
      pollfd p{socket.fd(), POLLIN, 0};
      const int wait_ms = static_cast<int>(clock_.io_timeout(stop, clock_.now() + kPoll, kPoll).count());
      if (::poll(&p, 1, wait_ms) > 0) {
        const ssize_t n = ::recv(socket.fd(), buffer.data(), buffer.size(), 0);
        if (n == 0) return fail("the VRPN server closed the connection");
        if (n < 0 && errno != EAGAIN && errno != EINTR)
          return fail(fmt::format("the connection broke: {}", std::strerror(errno)));
        if (n > 0) {
          auto messages = session.receive(std::span(buffer.data(), static_cast<std::size_t>(n)), clock_.now_us());
          if (!messages) return fail(messages.error().message);
          for (const auto& m : *messages) {
            if (m.sender != device) continue;  // another device served on the same connection
            last_heard = clock_.now();
            answered = true;
            if (m.type == kTrackerPosQuat) report(m, sink);
          }
        }
      }
      if (!session.ready()) {
        if (seconds_since(connected) > config_.connect_timeout_s)
          return fail(fmt::format("{} took the connection but sent no VRPN cookie within {:.1f} s: not a VRPN server?",
                                  config_.tracker.endpoint(), config_.connect_timeout_s));
        continue;
      }
      if (!announced) {
        sink.running(fmt::format("connected to {} ({})", config_.tracker.endpoint(), session.peer()->version));
        announced = true;
      }
      if (clock_.now() - last_ping >= kPingPeriod) {
        session.send(device, kPing, clock_.now_us(), {});
        last_ping = clock_.now();
      }
      if (seconds_since(last_heard) > config_.silence_timeout_s)
        return fail(answered ? fmt::format("nothing from '{}' for {:.1f} s", device, config_.silence_timeout_s)
                             : fmt::format("connected, but no device named '{}' answers there within {:.1f} s "
                                           "(VRPN names are case-sensitive)",
                                           device, config_.silence_timeout_s));
      lose_silent_sensors(sink);
    }
    return {};
  }

  void report(const NamedMessage& m, SampleSink& sink) {
    auto r = decode_pos_quat(m.payload);
    if (!r) {
      sink.count_error(r.error().message);
      return;
    }
    SensorState* sensor = sensor_for(r->sensor);
    if (!sensor) {
      sink.count_drop();
      return;
    }
    const std::int64_t arrival_us = clock_.now_us();
    std::int64_t t = m.time_us;
    if (std::llabs(t - arrival_us) > kMaxClockOffset_us) {
      if (!warned_clock_)
        sink.count_error(fmt::format("VRPN time stamps are {:.1f} s off this host's clock: using arrival times",
                                     static_cast<double>(t - arrival_us) * 1e-6));
      warned_clock_ = true;
      t = arrival_us;
    }
    PoseSample s{sensor->name, config_.parent_frame, sensor->name, t};
    s.T_parent_child = pose_of(*r);
    s.covariance = sensor->covariance;
    sink.pose(s);
    sensor->last = s.T_parent_child;
    sensor->last_report = clock_.now();
    sensor->reported = true;
  }

  // The configured sensor, or with no list a new "sensor<N>" with the device's covariance.
  SensorState* sensor_for(std::int32_t number) {
    if (const auto it = sensors_.find(number); it != sensors_.end()) return &it->second;
    if (!config_.sensors.empty() || number < 0 || number > kMaxSensorNumber || !config_.covariance) return nullptr;
    return &(sensors_[number] = SensorState{fmt::format("sensor{}", number), *config_.covariance});
  }

  void lose_silent_sensors(SampleSink& sink) {
    if (config_.sensor_timeout_s <= 0) return;
    for (auto& [number, s] : sensors_)
      if (s.reported && seconds_since(s.last_report) > config_.sensor_timeout_s) lose(s, sink);
  }

  void report_lost(SampleSink& sink) {
    for (auto& [number, s] : sensors_)
      if (s.reported) lose(s, sink);
  }

  void lose(SensorState& s, SampleSink& sink) {
    PoseSample lost{s.name, config_.parent_frame, s.name, clock_.now_us()};
    lost.status = TrackingStatus::Lost;
    lost.T_parent_child = s.last;
    lost.covariance = lost_covariance();
    sink.pose(lost);
    s.reported = false;
  }

  static constexpr std::int32_t kMaxSensorNumber = 65535;  // as the config allows
  double seconds_since(Clock::time_point t) const { return std::chrono::duration<double>(clock_.now() - t).count(); }

  VrpnConfig config_;
  DriverClock& clock_;
  std::map<std::int32_t, SensorState> sensors_;
  bool warned_clock_ = false;
};

}  // namespace

std::unique_ptr<Driver> make_vrpn_driver(const VrpnConfig& config, DriverClock& clock) {
  return std::make_unique<VrpnDriver>(config, clock);
}

}  // namespace covtrack::vrpn
