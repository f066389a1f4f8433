#include "hydra_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace covtrack::hydra {
namespace {

std::int16_t i16(const std::uint8_t* p) { return static_cast<std::int16_t>(p[0] | p[1] << 8); }
void put_i16(std::uint8_t* p, double v) {
  const auto x = static_cast<std::int16_t>(std::clamp(std::lround(v), -32768L, 32767L));
  p[0] = static_cast<std::uint8_t>(x & 0xFF);
  p[1] = static_cast<std::uint8_t>((static_cast<std::uint16_t>(x) >> 8) & 0xFF);
}

}  // namespace

Result<HydraReport> parse_hydra_report(std::span<const std::uint8_t> b) {
  if (b.size() != kReportSize)
    return fail(fmt::format("Hydra input report of {} bytes, expected {} (not in motion-controller "
                            "mode?)", b.size(), kReportSize));
  HydraReport r;
  for (int i = 0; i < 2; ++i) {
    const std::uint8_t* p = b.data() + kControllerOffset[i];
    auto& c = r.controllers[i];
    c.position_m = Vec3(i16(p), i16(p + 2), i16(p + 4)) * 1e-3;
    c.orientation = Eigen::Quaterniond(i16(p + 6) / 32768.0, i16(p + 8) / 32768.0,
                                       i16(p + 10) / 32768.0, i16(p + 12) / 32768.0);
    c.buttons = p[14];
    c.joystick_x = i16(p + 15) / 32768.0;
    c.joystick_y = i16(p + 17) / 32768.0;
    c.trigger = p[19] / 255.0;
    if (std::abs(c.orientation.norm() - 1.0) > 0.02)
      return fail(fmt::format("Hydra controller {}: quaternion norm {:.3f} is not 1", i,
                              c.orientation.norm()));
  }
  return r;
}

std::array<std::uint8_t, kReportSize> build_hydra_report(const HydraReport& r) {
  std::array<std::uint8_t, kReportSize> b{};
  for (int i = 0; i < 2; ++i) {
    std::uint8_t* p = b.data() + kControllerOffset[i];
    const auto& c = r.controllers[i];
    for (int k = 0; k < 3; ++k) put_i16(p + 2 * k, c.position_m[k] * 1e3);
    const auto& q = c.orientation;
    put_i16(p + 6, q.w() * 32768.0);
    put_i16(p + 8, q.x() * 32768.0);
    put_i16(p + 10, q.y() * 32768.0);
    put_i16(p + 12, q.z() * 32768.0);
    p[14] = c.buttons;
    put_i16(p + 15, c.joystick_x * 32768.0);
    put_i16(p + 17, c.joystick_y * 32768.0);
    p[19] = static_cast<std::uint8_t>(std::lround(std::clamp(c.trigger, 0.0, 1.0) * 255));
  }
  return b;
}

std::array<std::uint8_t, 91> motion_mode_feature_report() {
  std::array<std::uint8_t, 91> f{};  // f[0] = report id 0
  f[6] = 0x01;
  f[8] = 0x04;
  f[9] = 0x03;  // motion-controller mode
  f[89] = 0x06;
  return f;
}

std::array<std::uint8_t, 91> gamepad_mode_feature_report() {
  auto f = motion_mode_feature_report();
  f[9] = 0x00;
  f[89] = 0x05;
  return f;
}

Vec3 HemisphereTracker::resolve(int controller, const Vec3& reported) {
  auto& last = last_[static_cast<std::size_t>(controller)];
  Vec3 p = reported;
  if (last) {
    if ((p - *last).squaredNorm() > (-p - *last).squaredNorm()) p = -p;
  } else if ((controller == 0 && p.x() > 0) || (controller == 1 && p.x() < 0)) {
    p = -p;
  }
  last = p;
  return p;
}

}  // namespace covtrack::hydra
