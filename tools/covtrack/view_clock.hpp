#pragma once
// The pace of a view's frames (`covtrack view`, `covtrack ar`). Offline into a file (no
// live streams, no window) nothing outside sets it: frames are drawn at their scene or
// log times as fast as they can be, and the same command gives the same pictures.
// Otherwise frames follow the wall clock.
#include <chrono>
#include <thread>

namespace covtrack::cli {

class ViewClock {
 public:
  ViewClock(double fps, bool virtual_time) : period_s_(1.0 / fps), virtual_(virtual_time) {}

  // The view's time of frame `index` (s), after waiting for it on the wall clock.
  double frame_time_s(long index) const {
    if (virtual_) return index * period_s_;
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(index * period_s_)));
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  double period_s_;
  bool virtual_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace covtrack::cli
