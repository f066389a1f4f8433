#include "device_model.hpp"

#include <algorithm>
#include <array>
#include <numbers>

namespace covtrack::serial6dof {
namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kInch = 0.0254;

// Vendor spec-sheet figures: best case, metal-free; only the IS-900's 1.5 mm is
// confirmed by a published measurement, the rest are the vendors' usual numbers.
const std::array<ModelSpec, 5> kModels = {{
    {Model::Fastrak, Protocol::Fastrak, "fastrak", 0.03 * kInch, Vec3::Constant(0.15 * kDeg),
     120, true, 10, 0.004, 30 * kInch},
    {Model::Is900, Protocol::Fastrak, "is900", 1.5e-3, Vec3(0.25 * kDeg, 0.25 * kDeg, 0.5 * kDeg),
     180, false, 20, 0.004, 10.0},
    {Model::Liberty, Protocol::Liberty, "liberty", 0.03 * kInch, Vec3::Constant(0.15 * kDeg),
     240, false, 5, 0.0035, 30 * kInch},
    {Model::Patriot, Protocol::Liberty, "patriot", 0.06 * kInch, Vec3::Constant(0.40 * kDeg),
     60, false, 5, 0.0085, 30 * kInch},
    {Model::Flock, Protocol::Flock, "flock", 0.07 * kInch, Vec3::Constant(0.5 * kDeg),
     100, false, 10, 0.0075, 36 * kInch},
}};
}  // namespace

const ModelSpec& model_spec(Model model) {
  return *std::find_if(kModels.begin(), kModels.end(),
                       [&](const ModelSpec& s) { return s.model == model; });
}

const char* to_string(Protocol p) {
  switch (p) {
    case Protocol::Fastrak: return "fastrak";
    case Protocol::Liberty: return "liberty";
    case Protocol::Flock: return "flock";
  }
  return "?";
}

Protocol protocol_of(Model model) { return model_spec(model).protocol; }

Mat6 default_covariance(const ModelSpec& spec, const Mat3& R) {
  Mat6 c = Mat6::Zero();
  c.topLeftCorner<3, 3>() = Mat3::Identity() * spec.sigma_m * spec.sigma_m;
  const Mat3 D = spec.sigma_rad_parent.cwiseProduct(spec.sigma_rad_parent).asDiagonal();
  c.bottomRightCorner<3, 3>() = R.transpose() * D * R;
  return c;
}

double station_rate_hz(const ModelSpec& spec, int stations) {
  return spec.rate_is_shared ? spec.rate_hz / std::max(1, stations) : spec.rate_hz;
}

}  // namespace covtrack::serial6dof
