// An emulated Flock of Birds (Ascension laserBIRD guide, same RS-232 format): binary
// commands with fixed argument counts, 0xF0+address prefixes in group mode, answers to
// examine value.
#include <set>

#include "emulated_unit.hpp"

namespace covtrack::emulate6dof {
namespace {

using namespace serial6dof;

class FlockUnit final : public EmulatedUnit {
 public:
  explicit FlockUnit(const EmulatorConfig& config) : config_(config) { power_on(); }

  void power_on() override {
    streaming_ = false;
    group_mode_ = false;
    position_quaternion_.clear();
    target_ = 0;
  }

  bool handle(std::vector<std::uint8_t>& in, Bytes& reply) override {
    while (!in.empty()) {
      const std::uint8_t c = in.front();
      std::size_t used = 1;
      bool reset = false;
      if (c >= 0xF0) {
        target_ = c - 0xF0;  // the next command is for this bird
        in.erase(in.begin());
        continue;
      }
      switch (c) {
        case 'B': streaming_ = false; break;
        case 'G': streaming_ = false; break;  // sleep
        case '@': streaming_ = true; break;
        case ']':
          position_quaternion_.insert(target_ ? target_ : config_.stations.front().number);
          break;
        case 'O':  // examine: O param
          if (in.size() < 2) return false;
          used = 2;
          examine(in[1], reply);
          break;
        case 'P':  // change value: P param arg
          if (in.size() < 3) return false;
          used = 3;
          if (in[1] == 50) reset = true;             // FBB auto-configure: the long pause
          if (in[1] == 35) group_mode_ = in[2] != 0;
          break;
        default: break;
      }
      if (c != ']') target_ = 0;
      in.erase(in.begin(), in.begin() + static_cast<std::ptrdiff_t>(used));
      if (reset) return true;
    }
    return false;
  }

  bool streaming() const override { return streaming_; }

  Bytes encode(const std::vector<TrackerRecord>& records) const override {
    Bytes out;
    const FlockFormat f{config_.flock_scale_code == 1 ? 72.0 : 36.0, group_mode_,
                        config_.stations.front().number};
    for (const auto& r : records) {
      if (!position_quaternion_.count(r.station)) continue;  // other formats not emulated
      if (!group_mode_ && r.station != config_.stations.front().number) continue;
      append(out, encode_flock_record(r, f));
    }
    return out;
  }

  int trouble_code() const override { return -1; }  // records carry no status

 private:
  void examine(std::uint8_t param, Bytes& reply) const {
    if (param == 3) {  // position scaling
      reply.insert(reply.end(), {static_cast<std::uint8_t>(config_.flock_scale_code), 0});
    } else if (param == 36) {  // FBB system status: one byte per unit
      Bytes status(14, 0);
      for (const auto& s : config_.stations)
        if (s.number >= 1 && s.number <= 14) status[s.number - 1] = 0x80 | 0x40 | 0x20;
      reply.insert(reply.end(), status.begin(), status.end());
    } else {
      reply.insert(reply.end(), {0, 0});
    }
  }

  EmulatorConfig config_;
  bool streaming_ = false, group_mode_ = false;
  std::set<int> position_quaternion_;
  int target_ = 0;
};

}  // namespace

std::unique_ptr<EmulatedUnit> make_flock_unit(const EmulatorConfig& c) {
  return std::make_unique<FlockUnit>(c);
}

}  // namespace covtrack::emulate6dof
