#pragma once
// Pure decoder of Polhemus FASTRAK / InterSense IS-900 (Fastrak mode) output: binary pose
// records ('0', station, status, items..., terminator) and the ASCII status record
// ('2', station, 'S', ..., CR LF). Bytes in, items out; resyncs on the record header.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "resync_buffer.hpp"
#include "tracker_record.hpp"

namespace covtrack::serial6dof {

struct FastrakFormat {
  Units units = Units::Centimetres;
  std::vector<FastrakExtra> extras;
  bool crlf_terminator = true;  // item 1; false: item 0 (one space), as VRPN asks
};

// Bytes of one binary record in this format.
std::size_t fastrak_record_size(const FastrakFormat& format);
// The output-list command for a station: "O1,2,11,21,1\r".
std::string fastrak_output_list_command(int station, const FastrakFormat& format);

class FastrakDecoder {
 public:
  explicit FastrakDecoder(FastrakFormat format) : format_(std::move(format)) {}
  void set_format(const FastrakFormat& format) { format_ = format; }

  std::vector<DecodedItem> feed(std::span<const std::uint8_t> bytes);

  std::uint64_t resyncs() const { return input_.resyncs(); }        // runs of skipped bytes
  std::uint64_t bad_records() const { return input_.bad_records(); }  // framed but rejected
  const std::string& last_problem() const { return input_.last_problem(); }

 private:
  enum class Step { Item, NeedMore, Skip };
  Step try_record(std::vector<DecodedItem>& out);
  Step try_status(std::vector<DecodedItem>& out);

  FastrakFormat format_;
  ResyncBuffer input_;
};

// Units reported by a status record ('S' reply): system-flags bit 1 (0 inches, 1 cm);
// nullopt if the record is malformed.
std::optional<Units> fastrak_status_units(const DeviceReply& status);

// 1-based station from its ASCII digit ('1'-'9', then 'A'-'C' on the IS-900); 0 if invalid.
int fastrak_station_from_char(std::uint8_t c);
char fastrak_station_char(int station);

}  // namespace covtrack::serial6dof
