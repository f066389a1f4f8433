#pragma once
// Pure decoder of Polhemus LIBERTY / PATRIOT binary output (after F1): an 8-byte header
// (preamble "LY"/"PA"/"LU"/"PL"/"MM", station, command, error, reserved, int16 size)
// then `size` bytes. Pose frames answer 'C' (continuous) or 'P' (single); any other
// command comes back as a DeviceReply. Resyncs on the preamble.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "resync_buffer.hpp"
#include "tracker_record.hpp"

namespace covtrack::serial6dof {

struct LibertyFormat {
  Units units = Units::Centimetres;
  std::vector<LibertyExtra> extras;
};

inline constexpr std::size_t kLibertyHeaderSize = 8;
// Payload bytes of a pose frame in this format (items 2, 7, extras, then 1 = CR LF).
std::size_t liberty_payload_size(const LibertyFormat& format);
// "O1,2,7,8,1\r"
std::string liberty_output_list_command(int station, const LibertyFormat& format);

class LibertyDecoder {
 public:
  explicit LibertyDecoder(LibertyFormat format) : format_(std::move(format)) {}
  void set_format(const LibertyFormat& format) { format_ = format; }

  std::vector<DecodedItem> feed(std::span<const std::uint8_t> bytes);

  std::uint64_t resyncs() const { return input_.resyncs(); }
  std::uint64_t bad_records() const { return input_.bad_records(); }
  const std::string& last_problem() const { return input_.last_problem(); }

 private:
  void skip_to_next_preamble();
  LibertyFormat format_;
  ResyncBuffer input_;
};

bool is_liberty_preamble(std::uint8_t a, std::uint8_t b);
// The error byte: PDI's "no error" is 0, its ASCII form is a space.
inline bool liberty_error_is_ok(std::uint8_t e) { return e == 0x00 || e == 0x20; }

}  // namespace covtrack::serial6dof
