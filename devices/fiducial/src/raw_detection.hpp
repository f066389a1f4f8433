#pragma once
// The compact record of one frame's detections, published on covtrack/raw/<device> so
// that a session can be re-processed (another noise model, another tag map).
// Little-endian; layout in devices/fiducial/README.md ("Raw detections"):
//   "FTD1", u32 frame, i64 time_us, f32 image_noise, u16 count, then per tag:
//   i32 id, f32 decision_margin, f32 contrast, f32 corners[8] (u0 v0 .. u3 v3, OpenCV px),
//   u8 solutions (0-2), then per solution f32 t[3] (m), f32 rotvec[3] (rad), f32 sse_px2.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "tag_detector.hpp"
#include "tag_pose.hpp"

namespace covtrack::fiducial {

struct RawTag {
  Detection detection;
  double contrast = 0;
  std::vector<PoseSolution> solutions;  // best first
};

struct RawFrame {
  std::uint32_t frame = 0;
  std::int64_t time_us = 0;
  double image_noise = 0;
  std::vector<RawTag> tags;
};

std::vector<std::uint8_t> encode_raw_frame(const RawFrame& frame);
// nullopt on any malformed input (wrong magic, truncated, trailing bytes).
std::optional<RawFrame> decode_raw_frame(const std::uint8_t* data, std::size_t size);

}  // namespace covtrack::fiducial
