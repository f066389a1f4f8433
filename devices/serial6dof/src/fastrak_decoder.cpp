#include "fastrak_decoder.hpp"

#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "float_le.hpp"
#include "record_check.hpp"

namespace covtrack::serial6dof {
namespace {
constexpr std::size_t kMaxStatusRecord = 64;  // 55 on the Fastrak, 54 on some IS-900s

std::size_t extra_size(FastrakExtra e) {
  switch (e) {
    case FastrakExtra::Timestamp: return 4;  // float
    case FastrakExtra::Buttons: return 1;    // bit field
    case FastrakExtra::Stylus: return 2;     // space + '0'/'1'
    case FastrakExtra::Joystick: return 2;   // two bytes 0-255
  }
  return 0;
}
}  // namespace

int fastrak_station_from_char(std::uint8_t c) {
  if (c >= '1' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'C') return c - 'A' + 10;
  return 0;
}

char fastrak_station_char(int station) {
  return station < 10 ? static_cast<char>('0' + station) : static_cast<char>('A' + station - 10);
}

std::size_t fastrak_record_size(const FastrakFormat& f) {
  std::size_t n = 3 + 12 + 16 + (f.crlf_terminator ? 2 : 1);
  for (auto e : f.extras) n += extra_size(e);
  return n;
}

std::string fastrak_output_list_command(int station, const FastrakFormat& f) {
  std::string cmd = fmt::format("O{},2,11", station);
  for (auto e : f.extras) cmd += fmt::format(",{}", static_cast<int>(e));
  cmd += f.crlf_terminator ? ",1\r" : ",0\r";
  return cmd;
}

FastrakDecoder::Step FastrakDecoder::try_record(std::vector<DecodedItem>& out) {
  const std::size_t size = fastrak_record_size(format_);
  if (input_.size() < 3) return Step::NeedMore;
  const int station = fastrak_station_from_char(input_[1]);
  const std::uint8_t status = input_[2];
  const bool status_valid = status == ' ' || (status >= 'A' && status <= 'Z');
  if (station == 0 || !status_valid) return Step::Skip;  // not a header
  if (input_.size() < size) return Step::NeedMore;
  const std::uint8_t* p = input_.data();
  const bool end_ok = format_.crlf_terminator ? (p[size - 2] == '\r' && p[size - 1] == '\n')
                                              : p[size - 1] == ' ';
  if (!end_ok) {  // a cut record or garbage that looked like a header
    input_.reject("record without its terminator (cut or corrupt)");
    return Step::Skip;
  }
  TrackerRecord r;
  r.station = station;
  r.status_code = status;
  r.trouble = status != ' ';
  const double scale = metres_per_unit(format_.units);
  r.position_m = Vec3(read_float_le(p + 3), read_float_le(p + 7), read_float_le(p + 11)) * scale;
  r.orientation = Eigen::Quaterniond(read_float_le(p + 15), read_float_le(p + 19),
                                     read_float_le(p + 23), read_float_le(p + 27));
  std::size_t at = 31;
  for (auto e : format_.extras) {
    switch (e) {
      case FastrakExtra::Timestamp: r.device_time_s = read_float_le(p + at) * 1e-3; break;  // ms
      case FastrakExtra::Buttons: r.buttons = p[at]; break;
      case FastrakExtra::Stylus: r.buttons = p[at + 1] == '1' ? 1u : 0u; break;
      case FastrakExtra::Joystick: break;  // not a pose: read past it
    }
    at += extra_size(e);
  }
  if (const auto problem = record_problem(r)) {
    input_.reject(*problem);
    return Step::Skip;
  }
  out.emplace_back(std::move(r));
  input_.take(size);
  return Step::Item;
}

FastrakDecoder::Step FastrakDecoder::try_status(std::vector<DecodedItem>& out) {
  if (input_.size() < 3) return Step::NeedMore;
  const int station = fastrak_station_from_char(input_[1]);
  if (station == 0 || input_[2] != 'S') return Step::Skip;
  const std::size_t limit = std::min(input_.size(), kMaxStatusRecord);
  for (std::size_t i = 3; i < limit; ++i) {
    if (input_[i] != '\n') continue;
    const char* text = reinterpret_cast<const char*>(input_.data());
    out.emplace_back(DeviceReply{'S', station, 0, std::string(text, i + 1)});
    input_.take(i + 1);
    return Step::Item;
  }
  if (input_.size() >= kMaxStatusRecord) {
    input_.reject("status record without its line end");
    return Step::Skip;
  }
  return Step::NeedMore;
}

std::vector<DecodedItem> FastrakDecoder::feed(std::span<const std::uint8_t> bytes) {
  input_.append(bytes);
  std::vector<DecodedItem> out;
  while (!input_.empty()) {
    Step step = Step::Skip;
    if (input_[0] == '0') step = try_record(out);
    else if (input_[0] == '2') step = try_status(out);
    if (step == Step::NeedMore) break;
    // Binary records start with '0', status records with '2'.
    if (step == Step::Skip) input_.skip_to_next([](std::uint8_t b) { return b == '0' || b == '2'; });
  }
  return out;
}

std::optional<Units> fastrak_status_units(const DeviceReply& status) {
  const std::string& s = status.payload;
  if (status.command != 'S' || s.size() < 6) return std::nullopt;
  unsigned flags = 0;
  for (std::size_t i = 3; i < 6; ++i) {
    const char c = s[i];
    int digit = c == ' ' ? 0 : (c >= '0' && c <= '9') ? c - '0'
                : (c >= 'A' && c <= 'F') ? c - 'A' + 10 : (c >= 'a' && c <= 'f') ? c - 'a' + 10 : -1;
    if (digit < 0) return std::nullopt;
    flags = flags * 16 + static_cast<unsigned>(digit);
  }
  return (flags & 0x2u) ? Units::Centimetres : Units::Inches;
}

}  // namespace covtrack::serial6dof
