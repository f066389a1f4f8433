#include <cmath>

#include "covtrack/scene/scene.hpp"

namespace covtrack::scene {

SceneTransform scripted_value(const SceneTransform& t, double scene_time_s) {
  if (t.keyframes.empty()) return t;
  const std::vector<Keyframe>& k = t.keyframes;
  const double period = k.back().t_s;
  double at = period > 0 ? std::fmod(scene_time_s, period) : 0;
  if (at < 0) at += period;
  std::size_t i = 0;  // the keyframe at or before `at`
  while (i + 1 < k.size() && k[i + 1].t_s <= at) ++i;
  const Keyframe& a = k[i];
  const Keyframe& b = k[std::min(i + 1, k.size() - 1)];
  const double f = b.t_s > a.t_s ? (at - a.t_s) / (b.t_s - a.t_s) : 0;
  SceneTransform out = t;
  out.T_parent_child.translation() = a.position_m + f * (b.position_m - a.position_m);
  const double scale = a.sigma_scale + f * (b.sigma_scale - a.sigma_scale);
  out.covariance = t.covariance * (scale * scale);
  out.lost = a.lost;  // a status holds until the next keyframe; it does not blend
  return out;
}

}  // namespace covtrack::scene
