#pragma once
// AprilTag 3 detection on 8-bit grey frames. Corners come back in OpenCV's pixel
// convention (pixel centres at integers): AprilTag's are 0.5 px larger, and forgetting
// that offset biases every pose.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/protocol/result.hpp"
#include "tag_family.hpp"

struct apriltag_detector;

namespace covtrack::fiducial {

struct DetectorOptions {
  std::string family = "tag36h11";
  double decimate = 2;     // quads are searched on an image this much smaller
  double quad_sigma = 0;   // Gaussian blur before the quad search (px); ~0.8 helps on noise
  int threads = 1;
  int max_hamming = 1;     // bit errors corrected; more means more false positives
};

struct Detection {
  int id = 0;
  int hamming = 0;
  double decision_margin = 0;
  // AprilTag 3's order: the tag-frame corners (-s/2, +s/2), (+s/2, +s/2), (+s/2, -s/2),
  // (-s/2, -s/2) (x right, y down as printed).
  std::array<cv::Point2d, 4> corners_px;
};

class TagDetector {
 public:
  static Result<std::unique_ptr<TagDetector>> create(const DetectorOptions& options);
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  // The search's settings (decimate, quad_sigma, threads) for the next detections; the
  // family and the bit errors corrected stay as created (their decode table is what makes
  // creating a detector slow).
  Result<void> set_search(const DetectorOptions& options);

  // `gray` must be CV_8U, one channel.
  std::vector<Detection> detect(const cv::Mat& gray);
  const TagFamily& family() const { return *family_; }

 private:
  TagDetector(std::shared_ptr<TagFamily> family, apriltag_detector* detector);
  std::shared_ptr<TagFamily> family_;
  apriltag_detector* detector_;
};

}  // namespace covtrack::fiducial
