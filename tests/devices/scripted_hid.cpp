#include "scripted_hid.hpp"

#include <hidapi/hidapi.h>

#include <algorithm>
#include <cstring>

namespace covtrack::test {

void ScriptedHid::reset() {
  std::lock_guard l(m_);
  queue_.clear();
  open_ = unplugged_ = false;
  reads_until_unplugged_ = -1;
  feature_reports_ = 0;
}

void ScriptedHid::queue(std::span<const std::uint8_t> report) {
  std::lock_guard l(m_);
  queue_.emplace_back(report.begin(), report.end());
}

void ScriptedHid::unplug() {
  std::lock_guard l(m_);
  unplugged_ = true;
}

void ScriptedHid::unplug_after(int reads) {
  std::lock_guard l(m_);
  reads_until_unplugged_ = reads;
}

std::size_t ScriptedHid::waiting() const {
  std::lock_guard l(m_);
  return queue_.size();
}

int ScriptedHid::feature_reports() const {
  std::lock_guard l(m_);
  return feature_reports_;
}

bool ScriptedHid::open() const {
  std::lock_guard l(m_);
  return open_;
}

bool ScriptedHid::take_open() {
  std::lock_guard l(m_);
  if (open_ || unplugged_) return false;
  open_ = true;
  return true;
}

void ScriptedHid::close() {
  std::lock_guard l(m_);
  open_ = false;
}

// As hidraw: one report per read, cut to the buffer; none waiting is 0 (the driver's
// waits are on its clock); -1 once unplugged.
int ScriptedHid::read(std::uint8_t* data, std::size_t length) {
  std::lock_guard l(m_);
  if (reads_until_unplugged_ == 0) unplugged_ = true;
  if (unplugged_) return -1;
  if (queue_.empty()) return 0;
  if (reads_until_unplugged_ > 0) --reads_until_unplugged_;
  const std::size_t n = std::min(length, queue_.front().size());
  std::memcpy(data, queue_.front().data(), n);
  queue_.pop_front();
  return static_cast<int>(n);
}

void ScriptedHid::feature_report() {
  std::lock_guard l(m_);
  ++feature_reports_;
}

ScriptedHid& scripted_hid() {
  static ScriptedHid device;
  return device;
}

}  // namespace covtrack::test

// hidapi's opaque device: one, the scripted one.
struct hid_device_ {};

namespace {
hid_device_ the_device;
}

extern "C" {

int hid_init(void) { return 0; }

hid_device* hid_open_path(const char* path) {
  if (std::strcmp(path, covtrack::test::ScriptedHid::kPath) != 0) return nullptr;
  return covtrack::test::scripted_hid().take_open() ? &the_device : nullptr;
}

void hid_close(hid_device*) { covtrack::test::scripted_hid().close(); }

int hid_read_timeout(hid_device*, unsigned char* data, size_t length, int) {
  return covtrack::test::scripted_hid().read(data, length);
}

int hid_send_feature_report(hid_device*, const unsigned char*, size_t length) {
  covtrack::test::scripted_hid().feature_report();
  return static_cast<int>(length);
}

}  // extern "C"
