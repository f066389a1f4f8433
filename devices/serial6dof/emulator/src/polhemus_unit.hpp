#pragma once
// What the two Polhemus protocols' units (FASTRAK / IS-900, LIBERTY / PATRIOT) share:
// power-up settings (polled, ASCII, inches, no emulated output list), the switch to
// continuous output, and binary records for the stations whose output list it emulates.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "emulated_unit.hpp"

namespace covtrack::emulate6dof {

template <typename OutputList>
class PolhemusUnit : public EmulatedUnit {
 public:
  void power_on() override {
    units_ = serial6dof::Units::Inches;
    binary_ = false;
    continuous_ = false;
    lists_.clear();
  }

  bool streaming() const override { return continuous_; }

  Bytes encode(const std::vector<TrackerRecord>& records) const override {
    Bytes out;
    if (!binary_) return out;  // ASCII records are not emulated
    for (const auto& r : records)
      if (auto it = lists_.find(r.station); it != lists_.end()) append(out, encode_record(r, it->second));
    return out;  // a station still on its power-up list sends nothing: not emulated
  }

 protected:
  virtual Bytes encode_record(const TrackerRecord& record, const OutputList& list) const = 0;

  serial6dof::Units units_ = serial6dof::Units::Inches;
  bool binary_ = false, continuous_ = false;
  std::map<int, OutputList> lists_;  // by station
};

// The comma-separated fields of an output-list command's arguments ("1,2,11,1").
inline std::vector<std::string> comma_fields(const std::string& args) {
  std::vector<std::string> fields;
  for (std::size_t at = 0; at <= args.size();) {
    const auto comma = std::min(args.find(',', at), args.size());
    fields.push_back(args.substr(at, comma - at));
    at = comma + 1;
  }
  return fields;
}

}  // namespace covtrack::emulate6dof
