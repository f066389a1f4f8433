#include "covtrack/devices/serial6dof/flock_decoder.hpp"

#include "covtrack/devices/serial6dof/phased_word.hpp"
#include "record_check.hpp"

namespace covtrack::serial6dof {

std::size_t flock_record_size(const FlockFormat& f) { return f.group_mode ? 15 : 14; }

void FlockDecoder::skip_byte() {
  if (!skipping_) ++resyncs_;
  skipping_ = true;
  buffer_.erase(buffer_.begin());
}

std::vector<DecodedItem> FlockDecoder::feed(std::span<const std::uint8_t> bytes) {
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  std::vector<DecodedItem> out;
  const std::size_t size = flock_record_size(format_);
  while (!buffer_.empty()) {
    if (!(buffer_[0] & 0x80)) {  // not the first byte of a record
      skip_byte();
      continue;
    }
    // A phasing bit inside the record means the previous record was cut short.
    std::size_t cut = 0;
    for (std::size_t i = 1; i < std::min(size, buffer_.size()) && !cut; ++i)
      if (buffer_[i] & 0x80) cut = i;
    if (cut) {
      ++bad_records_;
      last_problem_ = "record cut short (phasing bit inside it)";
      if (!skipping_) ++resyncs_;
      skipping_ = true;
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(cut));
      continue;
    }
    if (buffer_.size() < size) break;
    const std::uint8_t* p = buffer_.data();
    double w[7];
    for (int i = 0; i < 7; ++i) w[i] = decode_phased_word(p[2 * i], p[2 * i + 1]);
    TrackerRecord r;
    r.station = format_.group_mode ? p[14] : format_.standalone_station;
    const double m_per_count = format_.position_scale_in * 0.0254 / 32768.0;
    r.position_m = Vec3(w[0], w[1], w[2]) * m_per_count;
    r.orientation = Eigen::Quaterniond(w[3] / 32768.0, w[4] / 32768.0, w[5] / 32768.0,
                                       w[6] / 32768.0);
    if (const auto problem = record_problem(r)) {
      ++bad_records_;
      last_problem_ = *problem;
      skip_byte();
      continue;
    }
    out.emplace_back(std::move(r));
    skipping_ = false;
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(size));
  }
  return out;
}

}  // namespace covtrack::serial6dof
