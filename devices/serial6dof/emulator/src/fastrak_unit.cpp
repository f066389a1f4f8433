// An emulated FASTRAK / IS-900 (Polhemus FASTRAK manual). Powers up polled, ASCII, inches,
// output list 2,4,1 (Euler: not emulated, so it sends no records until asked for 2,11).
#include <algorithm>
#include <map>
#include <string>

#include "emulated_unit.hpp"

namespace covtrack::emulate6dof {
namespace {

using namespace serial6dof;

class FastrakUnit final : public EmulatedUnit {
 public:
  explicit FastrakUnit(const EmulatorConfig& config) : config_(config) { power_on(); }

  void power_on() override {
    units_ = Units::Inches;
    binary_ = false;
    continuous_ = false;
    lists_.clear();
  }

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
        case 'S': {
          const Bytes s = encode_fastrak_status(config_.stations.front().number, units_);
          reply.insert(reply.end(), s.begin(), s.end());
          break;
        }
        default: break;  // CR, LF and unknown commands are ignored, as a unit does
      }
    }
    return false;
  }

  bool streaming() const override { return continuous_; }

  Bytes encode(const std::vector<TrackerRecord>& records) const override {
    Bytes out;
    if (!binary_) return out;  // ASCII records are not emulated
    for (const auto& r : records) {
      auto it = lists_.find(r.station);
      if (it == lists_.end()) continue;  // still the default list: not emulated
      const Bytes b = encode_fastrak_record(r, {units_, it->second.extras, it->second.crlf});
      out.insert(out.end(), b.begin(), b.end());
    }
    return out;
  }

  int trouble_code() const override { return 'B'; }  // a weak-signal letter

 private:
  struct OutputList {
    std::vector<FastrakExtra> extras;
    bool crlf = true;
  };

  // Accepts lists of the form 2,11[,extras...],0|1; anything else leaves the station
  // on a list this emulator does not produce.
  void set_output_list(const std::string& args) {
    std::vector<int> items;
    int station = 0;
    std::size_t at = 0;
    for (bool first = true; at <= args.size(); first = false) {
      const auto comma = std::min(args.find(',', at), args.size());
      const int v = std::atoi(args.substr(at, comma - at).c_str());
      if (first) station = v;
      else items.push_back(v);
      at = comma + 1;
    }
    lists_.erase(station);
    if (items.size() < 3 || items[0] != 2 || items[1] != 11) return;
    if (items.back() != 0 && items.back() != 1) return;
    OutputList list;
    list.crlf = items.back() == 1;
    for (std::size_t i = 2; i + 1 < items.size(); ++i) {
      if (items[i] != 21 && items[i] != 22 && items[i] != 16 && items[i] != 23) return;
      list.extras.push_back(static_cast<FastrakExtra>(items[i]));
    }
    lists_[station] = list;
  }

  EmulatorConfig config_;
  Units units_ = Units::Inches;
  bool binary_ = false, continuous_ = false;
  std::map<int, OutputList> lists_;
};

}  // namespace

std::unique_ptr<EmulatedUnit> make_fastrak_unit(const EmulatorConfig& c) {
  return std::make_unique<FastrakUnit>(c);
}

}  // namespace covtrack::emulate6dof
