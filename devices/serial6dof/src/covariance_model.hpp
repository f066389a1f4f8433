#pragma once
// The covariance reported with each record: the configured matrix or the model's static
// accuracy, inflated (and the status DEGRADED) when the unit flags the record or the
// receiver is beyond the range in which the accuracy is specified. The emulators draw
// their noise from this same function, so NEES tests check it end to end.
#include <optional>

#include "covtrack/protocol/pose_message.hpp"
#include "device_model.hpp"
#include "tracker_record.hpp"

namespace covtrack::serial6dof {

struct RecordUncertainty {
  Mat6 covariance;  // BODY convention
  TrackingStatus status = TrackingStatus::Ok;
};

// True when the record deserves the inflated covariance.
bool record_in_trouble(const TrackerRecord& record, const ModelSpec& spec);

RecordUncertainty record_uncertainty(const TrackerRecord& record, const ModelSpec& spec,
                                     const std::optional<Mat6>& configured, double inflation);

}  // namespace covtrack::serial6dof
