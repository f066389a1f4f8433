// An emulated FASTRAK / IS-900 (Polhemus FASTRAK manual). Powers up polled, ASCII, inches,
// output list 2,4,1 (Euler: not emulated, so it sends no records until asked for 2,11).
#include <algorithm>
#include <cstdlib>
#include <string>

#include "polhemus_unit.hpp"

namespace covtrack::emulate6dof {
namespace {

using namespace serial6dof;

struct FastrakList {
  std::vector<FastrakExtra> extras;
  bool crlf = true;
};

class FastrakUnit final : public PolhemusUnit<FastrakList> {
 public:
  explicit FastrakUnit(const EmulatorConfig& config) : config_(config) { power_on(); }

  bool handle(std::vector<std::uint8_t>& in, Bytes& reply) override {
    while (!in.empty()) {
      const std::uint8_t c = in.front();
      if (c == 'O') {  // O<station>,<items...><CR>
        auto cr = std::find(in.begin(), in.end(), '\r');
        if (cr == in.end()) return false;  // wait for the rest
        set_output_list(std::string(in.begin() + 1, cr));
        in.erase(in.begin(), cr + 1);
        continue;
      }
      in.erase(in.begin());
      switch (c) {
        case 0x19: return true;  // ^Y: reset
        case 'c': continuous_ = false; break;
        case 'C': continuous_ = true; break;
        case 'f': binary_ = true; break;
        case 'F': binary_ = false; break;
        case 'u': units_ = Units::Centimetres; break;
        case 'U': units_ = Units::Inches; break;
        case 'S': append(reply, encode_fastrak_status(config_.stations.front().number, units_)); break;
        default: break;  // CR, LF and unknown commands are ignored, as a unit does
      }
    }
    return false;
  }

  int trouble_code() const override { return 'B'; }  // a weak-signal letter

 private:
  Bytes encode_record(const TrackerRecord& r, const FastrakList& list) const override {
    return encode_fastrak_record(r, {units_, list.extras, list.crlf});
  }

  // Accepts lists of the form 2,11[,extras...],0|1; anything else leaves the station
  // on a list this emulator does not produce.
  void set_output_list(const std::string& args) {
    std::vector<int> items;
    for (const auto& field : comma_fields(args)) items.push_back(std::atoi(field.c_str()));
    const int station = items.front();
    items.erase(items.begin());
    lists_.erase(station);
    if (items.size() < 3 || items[0] != 2 || items[1] != 11) return;
    if (items.back() != 0 && items.back() != 1) return;
    FastrakList list;
    list.crlf = items.back() == 1;
    for (std::size_t i = 2; i + 1 < items.size(); ++i) {
      if (items[i] != 21 && items[i] != 22 && items[i] != 16 && items[i] != 23) return;
      list.extras.push_back(static_cast<FastrakExtra>(items[i]));
    }
    lists_[station] = list;
  }

  EmulatorConfig config_;
};

}  // namespace

std::unique_ptr<EmulatedUnit> make_fastrak_unit(const EmulatorConfig& c) {
  return std::make_unique<FastrakUnit>(c);
}

}  // namespace covtrack::emulate6dof
