#include "liberty_decoder.hpp"

#include <fmt/format.h>

#include "float_le.hpp"
#include "record_check.hpp"

namespace covtrack::serial6dof {
namespace {
// Longest frame accepted: who-am-I texts are a few hundred bytes.
constexpr std::size_t kMaxPayload = 1024;
}  // namespace

bool is_liberty_preamble(std::uint8_t a, std::uint8_t b) {
  return (a == 'L' && (b == 'Y' || b == 'U')) || (a == 'P' && (b == 'A' || b == 'L')) ||
         (a == 'M' && b == 'M');
}

std::size_t liberty_payload_size(const LibertyFormat& f) {
  return 12 + 16 + 4 * f.extras.size() + 2;
}

std::string liberty_output_list_command(int station, const LibertyFormat& f) {
  std::string cmd = fmt::format("O{},2,7", station);
  for (auto e : f.extras) cmd += fmt::format(",{}", static_cast<int>(e));
  return cmd + ",1\r";
}

void LibertyDecoder::skip_to_next_preamble() {
  input_.skip_to_next([](std::uint8_t b) { return b == 'L' || b == 'P' || b == 'M'; });
}

std::vector<DecodedItem> LibertyDecoder::feed(std::span<const std::uint8_t> bytes) {
  input_.append(bytes);
  std::vector<DecodedItem> out;
  while (input_.size() >= 2) {
    if (!is_liberty_preamble(input_[0], input_[1])) {
      skip_to_next_preamble();
      continue;
    }
    if (input_.size() < kLibertyHeaderSize) break;
    const std::uint8_t* h = input_.data();
    const std::size_t size = read_u16_le(h + 6);
    if (size > kMaxPayload || h[2] == 0) {  // a preamble look-alike inside data
      skip_to_next_preamble();
      continue;
    }
    if (input_.size() < kLibertyHeaderSize + size) break;
    const std::uint8_t* p = h + kLibertyHeaderSize;
    const char command = static_cast<char>(h[3]);
    if (command == 'C' || command == 'P') {
      if (size != liberty_payload_size(format_) || p[size - 2] != '\r' || p[size - 1] != '\n') {
        input_.reject(fmt::format("pose frame of {} bytes, expected {} ending in CR LF", size,
                                  liberty_payload_size(format_)));
        skip_to_next_preamble();
        continue;
      }
      TrackerRecord r;
      r.station = h[2];
      r.status_code = h[4];
      r.trouble = !liberty_error_is_ok(h[4]);
      const double scale = metres_per_unit(format_.units);
      r.position_m = Vec3(read_float_le(p), read_float_le(p + 4), read_float_le(p + 8)) * scale;
      r.orientation = Eigen::Quaterniond(read_float_le(p + 12), read_float_le(p + 16),
                                         read_float_le(p + 20), read_float_le(p + 24));
      std::size_t at = 28;
      for (auto e : format_.extras) {
        if (e == LibertyExtra::Timestamp) r.device_time_s = read_u32_le(p + at) * 1e-3;  // ms
        if (e == LibertyExtra::Stylus) r.buttons = read_u32_le(p + at);
        at += 4;
      }
      if (const auto problem = record_problem(r)) {
        input_.reject(*problem);
        skip_to_next_preamble();
        continue;
      }
      out.emplace_back(std::move(r));
    } else {
      out.emplace_back(DeviceReply{command, h[2], liberty_error_is_ok(h[4]) ? 0 : h[4],
                                   std::string(p, p + size)});
    }
    input_.take(kLibertyHeaderSize + size);
  }
  return out;
}

}  // namespace covtrack::serial6dof
