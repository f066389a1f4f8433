// An emulated LIBERTY / PATRIOT (Polhemus PDI SDK, VRPN's Liberty driver). Powers up
// polled, ASCII, inches. Commands end with CR, except P (single record, also ends
// continuous output).
#include <algorithm>
#include <cstdlib>
#include <string>

#include "polhemus_unit.hpp"

namespace covtrack::emulate6dof {
namespace {

using namespace serial6dof;

class LibertyUnit final : public PolhemusUnit<std::vector<LibertyExtra>> {
 public:
  explicit LibertyUnit(const EmulatorConfig& config)
      : config_(config), preamble_(config.model == Model::Patriot ? "PA" : "LY") {
    power_on();
  }

  bool handle(std::vector<std::uint8_t>& in, Bytes& reply) override {
    while (!in.empty()) {
      if (in.front() == 'P') {
        continuous_ = false;
        in.erase(in.begin());
        continue;
      }
      auto cr = std::find(in.begin(), in.end(), '\r');
      if (cr == in.end()) return false;
      const std::string cmd(in.begin(), cr);
      in.erase(in.begin(), cr + 1);
      if (cmd == "\x19") return true;
      if (cmd == "F0") binary_ = false;
      else if (cmd == "F1") binary_ = true;
      else if (cmd == "C") continuous_ = true;
      else if (cmd == "U0") units_ = Units::Inches;
      else if (cmd == "U1") units_ = Units::Centimetres;
      else if (cmd == "U") answer('U', setting(units_ == Units::Centimetres ? 1 : 0), reply);
      else if (cmd == "\x16") answer(0x16, who_am_i(), reply);
      else if (!cmd.empty() && cmd[0] == 'O') set_output_list(cmd.substr(1));
      // anything else (filters, hemisphere, CR alone) is accepted and ignored
    }
    return false;
  }

  int trouble_code() const override { return 0x05; }  // a non-zero PDI error code

 private:
  Bytes encode_record(const TrackerRecord& r, const std::vector<LibertyExtra>& extras) const override {
    return encode_liberty_record(r, {units_, extras}, preamble_);
  }
  static Bytes setting(std::uint32_t v) {
    return {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
            static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)};
  }
  Bytes who_am_i() const {
    const std::string text = std::string(config_.model == Model::Patriot ? "PATRIOT" : "LIBERTY") +
                             " (covtrack emulator)\r\nBoard Rev: emulated\r\n";
    return Bytes(text.begin(), text.end());
  }
  void answer(char command, const Bytes& payload, Bytes& reply) const {
    append(reply, binary_ ? encode_liberty_frame(1, command, 0, payload, preamble_) : payload);
  }
  // Accepts O<st>,2,7[,8|9|10...],1; "*" means every station.
  void set_output_list(const std::string& args) {
    const std::vector<std::string> parts = comma_fields(args);
    std::vector<int> stations;
    if (parts[0] == "*") for (const auto& s : config_.stations) stations.push_back(s.number);
    else stations.push_back(std::atoi(parts[0].c_str()));
    for (int st : stations) lists_.erase(st);
    if (parts.size() < 4 || parts[1] != "2" || parts[2] != "7" || parts.back() != "1") return;
    std::vector<LibertyExtra> extras;
    for (std::size_t i = 3; i + 1 < parts.size(); ++i) {
      const int item = std::atoi(parts[i].c_str());
      if (item < 8 || item > 10) return;
      extras.push_back(static_cast<LibertyExtra>(item));
    }
    for (int st : stations) lists_[st] = extras;
  }

  EmulatorConfig config_;
  const char* preamble_;
};

}  // namespace

std::unique_ptr<EmulatedUnit> make_liberty_unit(const EmulatorConfig& c) {
  return std::make_unique<LibertyUnit>(c);
}

}  // namespace covtrack::emulate6dof
