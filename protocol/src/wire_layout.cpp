#include "wire_layout.hpp"

#include <covtrack/device_claim_t.hpp>
#include <covtrack/device_status_t.hpp>
#include <covtrack/image_t.hpp>
#include <covtrack/pose_cov_t.hpp>
#include <covtrack/raw_bytes_t.hpp>
#include <covtrack/truth_pose_t.hpp>

namespace covtrack::wire {
namespace {

constexpr Field kPose[] = {
    {"measurement_time_us", Kind::I64}, {"publish_time_us", Kind::I64}, {"sequence", Kind::I64},
    {"device", Kind::Name},             {"sensor", Kind::Name},         {"parent_frame", Kind::Label},
    {"child_frame", Kind::Label},       {"position_m", Kind::F64, 3},   {"orientation_wxyz", Kind::F64, 4},
    {"covariance", Kind::F64, 36},      {"covariance_convention", Kind::I8}, {"status", Kind::I8},
};

constexpr Field kTruth[] = {
    {"measurement_time_us", Kind::I64}, {"sequence", Kind::I64},         {"device", Kind::Name},
    {"sensor", Kind::Name},             {"parent_frame", Kind::Label},   {"child_frame", Kind::Label},
    {"position_m", Kind::F64, 3},       {"orientation_wxyz", Kind::F64, 4},
};

constexpr Field kStatus[] = {
    {"time_us", Kind::I64}, {"device", Kind::Name},    {"driver", Kind::Label}, {"state", Kind::I8},
    {"rate_hz", Kind::F64}, {"reports", Kind::I64},    {"errors", Kind::I64},   {"resyncs", Kind::I64},
    {"drops", Kind::I64},   {"restarts", Kind::I64},   {"last_error", Kind::Text}, {"detail", Kind::Text},
    {"instance_id", Kind::I64}, {"host", Kind::Label}, {"pid", Kind::I32}, {"heartbeat_period_us", Kind::I64},
};

constexpr Field kClaim[] = {
    {"time_us", Kind::I64},     {"device", Kind::Name}, {"instance_id", Kind::I64}, {"host", Kind::Label},
    {"pid", Kind::I32},         {"claimed_us", Kind::I64}, {"stage", Kind::I8},
};

constexpr Field kRaw[] = {
    {"time_us", Kind::I64}, {"device", Kind::Name}, {"direction", Kind::I8}, {"length", Kind::I32},
    {"data", Kind::Bytes},
};

constexpr Field kImage[] = {
    {"measurement_time_us", Kind::I64}, {"device", Kind::Name}, {"width", Kind::I32}, {"height", Kind::I32},
    {"encoding", Kind::Label},          {"size", Kind::I32},    {"data", Kind::Bytes},
};

}  // namespace

// The fingerprints are lcm-gen's for the field lists above (Msg::getHash()).
template <>
const Layout& layout_of<pose_cov_t>() {
  static const Layout l{"pose_cov_t", 0x7df218e084063fd2, kPose};
  return l;
}
template <>
const Layout& layout_of<truth_pose_t>() {
  static const Layout l{"truth_pose_t", 0x5f660fe518a5d595, kTruth};
  return l;
}
template <>
const Layout& layout_of<device_status_t>() {
  static const Layout l{"device_status_t", 0x7ec722603176c7fd, kStatus};
  return l;
}
template <>
const Layout& layout_of<device_claim_t>() {
  static const Layout l{"device_claim_t", 0x33b158b34d7502e8, kClaim};
  return l;
}
template <>
const Layout& layout_of<raw_bytes_t>() {
  static const Layout l{"raw_bytes_t", 0xfa0617e1cacb6101, kRaw};
  return l;
}
template <>
const Layout& layout_of<image_t>() {
  static const Layout l{"image_t", 0x0a582eed010a255d, kImage};
  return l;
}

}  // namespace covtrack::wire
