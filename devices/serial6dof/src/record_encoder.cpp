#include "record_encoder.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <iterator>

#include <fmt/format.h>

#include "phased_word.hpp"

namespace covtrack::serial6dof {
namespace {
void put_u32(Bytes& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_float(Bytes& b, double v) { put_u32(b, std::bit_cast<std::uint32_t>(static_cast<float>(v))); }
void put_pose(Bytes& b, const TrackerRecord& r, Units units) {
  const Vec3 p = r.position_m / metres_per_unit(units);
  for (int i = 0; i < 3; ++i) put_float(b, p[i]);
  const auto& q = r.orientation;
  for (double v : {q.w(), q.x(), q.y(), q.z()}) put_float(b, v);
}
std::int16_t to_word(double value, double full_scale) {
  const double counts = std::clamp(std::round(value / full_scale * 32768.0), -32768.0, 32767.0);
  return static_cast<std::int16_t>(counts);
}
}  // namespace

Bytes encode_fastrak_record(const TrackerRecord& r, const FastrakFormat& f) {
  Bytes b = {'0', static_cast<std::uint8_t>(fastrak_station_char(r.station)),
             static_cast<std::uint8_t>(r.status_code ? r.status_code : ' ')};
  put_pose(b, r, f.units);
  for (auto e : f.extras) {
    switch (e) {
      case FastrakExtra::Timestamp: put_float(b, r.device_time_s.value_or(0) * 1e3); break;
      case FastrakExtra::Buttons: b.push_back(static_cast<std::uint8_t>(r.buttons.value_or(0))); break;
      case FastrakExtra::Stylus: b.insert(b.end(), {' ', r.buttons.value_or(0) ? std::uint8_t('1') : std::uint8_t('0')}); break;
      case FastrakExtra::Joystick: b.insert(b.end(), {127, 127}); break;
    }
  }
  if (f.crlf_terminator) b.insert(b.end(), {'\r', '\n'});
  else b.push_back(' ');
  return b;
}

Bytes encode_fastrak_status(int station, Units units) {
  // '2', station, 'S', 3 hex system flags, 3 BIT-error chars, 6 blanks, 6-char software
  // version, 32-char system id, CR LF: 55 bytes.
  const std::string s = fmt::format("2{}S{:03X}{:>3}{:6}{:>6}{:<32}\r\n", fastrak_station_char(station),
                                    units == Units::Centimetres ? 0x2 : 0x0, 0, "", "3.00",
                                    "covtrack emulator");
  return Bytes(s.begin(), s.end());
}

Bytes encode_liberty_frame(int station, char command, std::uint8_t error, const Bytes& payload,
                           const char preamble[2]) {
  const std::uint8_t header[] = {static_cast<std::uint8_t>(preamble[0]), static_cast<std::uint8_t>(preamble[1]),
                                 static_cast<std::uint8_t>(station), static_cast<std::uint8_t>(command), error, 0,
                                 static_cast<std::uint8_t>(payload.size() & 0xFF),
                                 static_cast<std::uint8_t>(payload.size() >> 8)};
  // Sized once and copied into: GCC 12 warns (-Warray-bounds, falsely) on an insert after
  // an initializer-list construction.
  Bytes b(sizeof header + payload.size());
  std::copy(std::begin(header), std::end(header), b.begin());
  std::copy(payload.begin(), payload.end(), b.begin() + sizeof header);
  return b;
}

Bytes encode_liberty_record(const TrackerRecord& r, const LibertyFormat& f, const char preamble[2]) {
  Bytes payload;
  put_pose(payload, r, f.units);
  for (auto e : f.extras) {
    if (e == LibertyExtra::Timestamp)
      put_u32(payload, static_cast<std::uint32_t>(std::llround(r.device_time_s.value_or(0) * 1e3)));
    else if (e == LibertyExtra::Stylus) put_u32(payload, r.buttons.value_or(0));
    else put_u32(payload, 0);
  }
  payload.insert(payload.end(), {'\r', '\n'});
  return encode_liberty_frame(r.station, 'C', static_cast<std::uint8_t>(r.status_code), payload,
                              preamble);
}

Bytes encode_flock_record(const TrackerRecord& r, const FlockFormat& f) {
  const double full_scale_m = f.position_scale_in * 0.0254;
  const auto& q = r.orientation;
  const double values[7] = {r.position_m.x() / full_scale_m, r.position_m.y() / full_scale_m,
                            r.position_m.z() / full_scale_m, q.w(), q.x(), q.y(), q.z()};
  Bytes b(flock_record_size(f));
  for (int i = 0; i < 7; ++i) encode_phased_word(to_word(values[i], 1.0), i == 0, &b[2 * i]);
  if (f.group_mode) b[14] = static_cast<std::uint8_t>(r.station & 0x7F);
  return b;
}

}  // namespace covtrack::serial6dof
