// Flock of Birds configuration (laserBIRD guide, same RS-232 format): B (stop streaming),
// P 50 n (FBB auto-configuration, the long reset), O 3 (examine position scaling: confirms
// the units), P 35 g (group mode), ] per bird (POSITION/QUATERNION), @ (stream).
#include <fmt/format.h>

#include "device_session.hpp"
#include "flock_decoder.hpp"

namespace covtrack::serial6dof {
namespace {

constexpr char kPoint = 'B', kStream = '@', kChangeValue = 'P', kExamineValue = 'O';
constexpr char kPositionQuaternion = ']';
constexpr char kParamPositionScaling = 3, kParamGroupMode = 35, kParamAutoConfig = 50;
constexpr unsigned char kToBird = 0xF0;  // + address: forwards the next command to that bird

std::string bytes(std::initializer_list<int> values) {
  std::string s;
  for (int v : values) s.push_back(static_cast<char>(v));
  return s;
}

FlockFormat format_of(const Serial6dofConfig& c) {
  return {c.flock_position_scale_in, c.stations.size() > 1, c.stations.front().number};
}

class FlockSession final : public DecodingSession<FlockDecoder> {
 public:
  explicit FlockSession(const Serial6dofConfig& c) : DecodingSession(c, format_of(c)) {}

  Result<void> start(DeviceLink& link, bool reset) override {
    using namespace std::chrono_literals;
    const bool group = config_.stations.size() > 1;
    if (auto r = link.send(bytes({kPoint})); !r) return r;
    if (auto r = link.drain(100ms); !r) return r;
    if (reset) {
      const int birds = std::max_element(config_.stations.begin(), config_.stations.end(),
                                         [](auto& a, auto& b) { return a.number < b.number; })->number;
      if (auto r = link.send(bytes({kChangeValue, kParamAutoConfig, birds})); !r) return r;
      if (!link.sleep(config_.reset_time_s)) return {};
      if (auto r = link.drain(50ms); !r) return r;
    }
    if (auto r = confirm_scaling(link); !r) return r;
    if (link.stopped()) return {};
    if (auto r = link.send(bytes({kChangeValue, kParamGroupMode, group ? 1 : 0})); !r) return r;
    for (const auto& st : config_.stations) {
      const std::string cmd = group ? bytes({kToBird + st.number, kPositionQuaternion})
                                    : bytes({kPositionQuaternion});
      if (auto r = link.send(cmd); !r) return r;
    }
    return link.send(bytes({kStream}));
  }

 private:
  // The answer to an examine is two raw bytes (LS first), outside any record framing.
  Result<void> confirm_scaling(DeviceLink& link) {
    if (auto r = link.send(bytes({kExamineValue, kParamPositionScaling})); !r) return r;
    std::vector<std::uint8_t> answer;
    const auto deadline = link.after(config_.reply_timeout_s);
    while (answer.size() < 2 && !link.stopped() && link.clock().now() < deadline)
      if (auto n = link.read(answer, std::chrono::milliseconds(20)); !n) return std::unexpected(n.error());
    if (link.stopped()) return {};
    if (answer.size() < 2)
      return no_answer(link,
                       fmt::format("no answer to examine position scaling within {} s", config_.reply_timeout_s),
                       "the bird is on and not asleep");
    const int code = answer[0] | answer[1] << 8;
    // 0: 36 in, 1: 72 in (standard transmitter). The extended-range transmitter's 144 in
    // is not reported by this parameter, so it cannot be confirmed here.
    if (config_.flock_position_scale_in == 144) return {};
    const double reported = code == 0 ? 36 : code == 1 ? 72 : -1;
    if (reported != config_.flock_position_scale_in)
      return fail(fmt::format("{}: units not confirmed: the bird's position scaling is {} "
                              "(code {}), position_scale_in = {} was configured", link.path(),
                              reported < 0 ? std::string("unknown") : fmt::format("{} in", reported),
                              code, config_.flock_position_scale_in));
    return {};
  }

};

}  // namespace

std::unique_ptr<DeviceSession> make_flock_session(const Serial6dofConfig& c) {
  return std::make_unique<FlockSession>(c);
}

}  // namespace covtrack::serial6dof
