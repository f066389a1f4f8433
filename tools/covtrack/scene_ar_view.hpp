#pragma once
// The per-frame AR API (client::ArView) for a scene's camera and objects, with the 2-D
// viewer's options (projection, confidence, assessment, label boxes that fit the viewer's
// label text), so that `covtrack ar` and `covtrack view` agree frame by frame.
#include <opencv2/core.hpp>

#include "covtrack/client/ar_view.hpp"
#include "covtrack/protocol/result.hpp"
#include "regions_report.hpp"

namespace covtrack::cli {

Result<client::ArView> scene_ar_view(const RegionsModel& model, const cv::Size& screen,
                                     client::ProjectionMethod method = client::ProjectionMethod::unscented);

}  // namespace covtrack::cli
