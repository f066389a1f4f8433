#include "tag_detector.hpp"

#include <apriltag/apriltag.h>
#include <fmt/format.h>

namespace covtrack::fiducial {

// AprilTag puts a pixel's centre at (i + 0.5); OpenCV, the renderer and the camera
// calibration put it at i.
constexpr double kAprilTagPixelOffset = 0.5;

Result<std::unique_ptr<TagDetector>> TagDetector::create(const DetectorOptions& o) {
  auto family = TagFamily::open(o.family);
  if (!family) return std::unexpected(family.error());
  if (o.max_hamming < 0 || o.max_hamming > 3)
    return fail(fmt::format("invalid detector options: max_hamming {} (0-3)", o.max_hamming));
  apriltag_detector_t* td = apriltag_detector_create();
  std::unique_ptr<TagDetector> detector(new TagDetector(std::move(*family), td));
  if (auto set = detector->set_search(o); !set) return std::unexpected(set.error());
  apriltag_detector_add_family_bits(td, detector->family_->get(), o.max_hamming);
  td->refine_edges = 1;
  return detector;
}

Result<void> TagDetector::set_search(const DetectorOptions& o) {
  if (!(o.decimate >= 1) || !(o.quad_sigma >= 0) || o.threads < 1)
    return fail(fmt::format("invalid detector options: decimate {} (>= 1), quad_sigma {} (>= 0), threads {} (>= 1)",
                            o.decimate, o.quad_sigma, o.threads));
  detector_->quad_decimate = static_cast<float>(o.decimate);
  detector_->quad_sigma = static_cast<float>(o.quad_sigma);
  detector_->nthreads = o.threads;
  return {};
}

TagDetector::TagDetector(std::shared_ptr<TagFamily> family, apriltag_detector* detector)
    : family_(std::move(family)), detector_(detector) {}

TagDetector::~TagDetector() { apriltag_detector_destroy(detector_); }

std::vector<Detection> TagDetector::detect(const cv::Mat& gray) {
  CV_Assert(gray.type() == CV_8UC1);
  image_u8_t im{gray.cols, gray.rows, static_cast<int32_t>(gray.step), gray.data};
  zarray_t* found = apriltag_detector_detect(detector_, &im);
  std::vector<Detection> out;
  for (int i = 0; i < zarray_size(found); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(found, i, &d);
    Detection det;
    det.id = d->id;
    det.hamming = d->hamming;
    det.decision_margin = d->decision_margin;
    for (int k = 0; k < 4; ++k)
      det.corners_px[k] = {d->p[k][0] - kAprilTagPixelOffset, d->p[k][1] - kAprilTagPixelOffset};
    out.push_back(det);
  }
  apriltag_detections_destroy(found);
  return out;
}

}  // namespace covtrack::fiducial
