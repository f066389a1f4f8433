#include "resync_buffer.hpp"

#include <utility>

namespace covtrack::serial6dof {

void ResyncBuffer::append(std::span<const std::uint8_t> bytes) {
  // Once per read, not once per byte: what is dropped here was passed over in one go.
  bytes_.erase(bytes_.begin(), bytes_.begin() + static_cast<std::ptrdiff_t>(start_));
  start_ = 0;
  bytes_.insert(bytes_.end(), bytes.begin(), bytes.end());
}

void ResyncBuffer::take(std::size_t n) {
  start_ += std::min(n, size());
  skipping_ = false;
}

void ResyncBuffer::skip(std::size_t n) {
  if (n == 0) return;
  if (!skipping_) ++resyncs_;
  skipping_ = true;
  start_ += std::min(n, size());
}

void ResyncBuffer::reject(std::string problem) {
  ++bad_records_;
  last_problem_ = std::move(problem);
}

}  // namespace covtrack::serial6dof
