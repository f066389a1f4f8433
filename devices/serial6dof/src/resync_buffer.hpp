#pragma once
// What every serial 6-DOF decoder keeps between reads: the bytes not decoded yet, and the
// bookkeeping of getting back in step after line noise or a corrupt record (resyncs,
// rejected records, the last reason for a rejection).
//
// Skipping is cheap on purpose: taking or skipping bytes only moves an offset, and the
// bytes behind it are dropped once per append(). Erasing the front of a vector byte by
// byte cost time quadratic in a run of noise, on the driver's read path.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace covtrack::serial6dof {

class ResyncBuffer {
 public:
  // Adds bytes as they came from the device.
  void append(std::span<const std::uint8_t> bytes);

  // The bytes not yet taken or skipped.
  std::size_t size() const { return bytes_.size() - start_; }
  bool empty() const { return size() == 0; }
  const std::uint8_t* data() const { return bytes_.data() + start_; }
  std::uint8_t operator[](std::size_t i) const { return bytes_[start_ + i]; }

  // A record or reply of `n` bytes was decoded: the stream is in step.
  void take(std::size_t n);
  // `n` bytes start nothing. A run of skipped bytes counts as one resync.
  void skip(std::size_t n);
  // Skips the first byte, then everything before the next byte that `could_start` a
  // record or reply (all of it if none does).
  template <typename Predicate>
  void skip_to_next(Predicate could_start) {
    if (empty()) return;
    const auto begin = bytes_.begin() + static_cast<std::ptrdiff_t>(start_);
    const auto next = std::find_if(begin + 1, bytes_.end(), could_start);
    skip(static_cast<std::size_t>(next - begin));
  }
  // A framed record the decoder refused (cut, corrupt): counted, with the reason.
  void reject(std::string problem);

  std::uint64_t resyncs() const { return resyncs_; }        // runs of skipped bytes
  std::uint64_t bad_records() const { return bad_records_; }  // framed but refused
  const std::string& last_problem() const { return last_problem_; }

 private:
  std::vector<std::uint8_t> bytes_;
  std::size_t start_ = 0;  // bytes_[0, start_) are taken or skipped, kept until append()
  bool skipping_ = false;
  std::uint64_t resyncs_ = 0, bad_records_ = 0;
  std::string last_problem_;
};

}  // namespace covtrack::serial6dof
