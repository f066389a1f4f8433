#include "raw_detection.hpp"

#include <cstring>

namespace covtrack::fiducial {
namespace {

class Writer {
 public:
  template <typename T>
  void put(T v) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));  // the hosts covtrack runs on are little-endian
    out.insert(out.end(), b, b + sizeof(T));
  }
  void f32(double v) { put(static_cast<float>(v)); }
  std::vector<std::uint8_t> out;
};

class Reader {
 public:
  Reader(const std::uint8_t* d, std::size_t n) : d_(d), n_(n) {}
  template <typename T>
  bool get(T& v) {
    if (n_ - i_ < sizeof(T)) return false;
    std::memcpy(&v, d_ + i_, sizeof(T));
    i_ += sizeof(T);
    return true;
  }
  bool f32(double& v) {
    float f;
    if (!get(f)) return false;
    v = f;
    return true;
  }
  bool done() const { return i_ == n_; }

 private:
  const std::uint8_t* d_;
  std::size_t n_, i_ = 0;
};

constexpr char kMagic[4] = {'F', 'T', 'D', '1'};

}  // namespace

std::vector<std::uint8_t> encode_raw_frame(const RawFrame& f) {
  Writer w;
  for (char c : kMagic) w.put(c);
  w.put(f.frame);
  w.put(f.time_us);
  w.f32(f.image_noise);
  w.put(static_cast<std::uint16_t>(f.tags.size()));
  for (const RawTag& t : f.tags) {
    w.put(static_cast<std::int32_t>(t.detection.id));
    w.f32(t.detection.decision_margin);
    w.f32(t.contrast);
    for (const auto& p : t.detection.corners_px) w.f32(p.x), w.f32(p.y);
    const auto n = static_cast<std::uint8_t>(std::min<std::size_t>(t.solutions.size(), 2));
    w.put(n);
    for (std::uint8_t i = 0; i < n; ++i) {
      const Pose& T = t.solutions[i].T_camera_tag;
      const Vec3 rotvec = so3_log(T.rotation());
      for (int k = 0; k < 3; ++k) w.f32(T.translation()[k]);
      for (int k = 0; k < 3; ++k) w.f32(rotvec[k]);
      w.f32(t.solutions[i].sse_px2);
    }
  }
  return std::move(w.out);
}

std::optional<RawFrame> decode_raw_frame(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size);
  char magic[4];
  for (char& c : magic)
    if (!r.get(c)) return std::nullopt;
  if (std::memcmp(magic, kMagic, 4) != 0) return std::nullopt;
  RawFrame f;
  std::uint16_t count = 0;
  if (!r.get(f.frame) || !r.get(f.time_us) || !r.f32(f.image_noise) || !r.get(count)) return std::nullopt;
  for (std::uint16_t i = 0; i < count; ++i) {
    RawTag t;
    std::int32_t id;
    std::uint8_t n;
    if (!r.get(id) || !r.f32(t.detection.decision_margin) || !r.f32(t.contrast)) return std::nullopt;
    t.detection.id = id;
    for (auto& p : t.detection.corners_px)
      if (!r.f32(p.x) || !r.f32(p.y)) return std::nullopt;
    if (!r.get(n) || n > 2) return std::nullopt;
    for (std::uint8_t s = 0; s < n; ++s) {
      Vec3 t3, rv;
      PoseSolution sol;
      for (int k = 0; k < 3; ++k)
        if (!r.f32(t3[k])) return std::nullopt;
      for (int k = 0; k < 3; ++k)
        if (!r.f32(rv[k])) return std::nullopt;
      if (!r.f32(sol.sse_px2)) return std::nullopt;
      sol.T_camera_tag = Pose::Identity();
      sol.T_camera_tag.linear() = so3_exp(rv);
      sol.T_camera_tag.translation() = t3;
      t.solutions.push_back(sol);
    }
    f.tags.push_back(std::move(t));
  }
  if (!r.done()) return std::nullopt;
  return f;
}

}  // namespace covtrack::fiducial
