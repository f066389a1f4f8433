#include "flock_decoder.hpp"

#include "phased_word.hpp"
#include "record_check.hpp"

namespace covtrack::serial6dof {

std::size_t flock_record_size(const FlockFormat& f) { return f.group_mode ? 15 : 14; }

void FlockDecoder::skip_to_next_record() {
  input_.skip_to_next([](std::uint8_t b) { return (b & 0x80) != 0; });
}

std::vector<DecodedItem> FlockDecoder::feed(std::span<const std::uint8_t> bytes) {
  input_.append(bytes);
  std::vector<DecodedItem> out;
  const std::size_t size = flock_record_size(format_);
  while (!input_.empty()) {
    if (!(input_[0] & 0x80)) {  // not the first byte of a record
      skip_to_next_record();
      continue;
    }
    // A phasing bit inside the record means the previous record was cut short.
    std::size_t cut = 0;
    for (std::size_t i = 1; i < std::min(size, input_.size()) && !cut; ++i)
      if (input_[i] & 0x80) cut = i;
    if (cut) {
      input_.reject("record cut short (phasing bit inside it)");
      input_.skip(cut);
      continue;
    }
    if (input_.size() < size) break;
    const std::uint8_t* p = input_.data();
    double w[7];
    for (int i = 0; i < 7; ++i) w[i] = decode_phased_word(p[2 * i], p[2 * i + 1]);
    TrackerRecord r;
    r.station = format_.group_mode ? p[14] : format_.standalone_station;
    const double m_per_count = format_.position_scale_in * 0.0254 / 32768.0;
    r.position_m = Vec3(w[0], w[1], w[2]) * m_per_count;
    r.orientation = Eigen::Quaterniond(w[3] / 32768.0, w[4] / 32768.0, w[5] / 32768.0,
                                       w[6] / 32768.0);
    if (const auto problem = record_problem(r)) {
      input_.reject(*problem);
      skip_to_next_record();
      continue;
    }
    out.emplace_back(std::move(r));
    input_.take(size);
  }
  return out;
}

}  // namespace covtrack::serial6dof
