#include "covariance_model.hpp"

namespace covtrack::serial6dof {

bool record_in_trouble(const TrackerRecord& r, const ModelSpec& spec) {
  return r.trouble || r.position_m.norm() > spec.specified_range_m;
}

RecordUncertainty record_uncertainty(const TrackerRecord& r, const ModelSpec& spec,
                                     const std::optional<Mat6>& configured, double inflation) {
  RecordUncertainty u;
  u.covariance = configured ? *configured
                            : default_covariance(spec, r.orientation.normalized().toRotationMatrix());
  if (record_in_trouble(r, spec)) {
    u.covariance *= inflation;
    u.status = TrackingStatus::Degraded;
  }
  return u;
}

}  // namespace covtrack::serial6dof
