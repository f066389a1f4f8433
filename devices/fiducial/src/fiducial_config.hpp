#pragma once
// Options of the AprilTag fiducial tracker (type = "fiducial"), read from its
// [devices.<name>] table, its [[devices.<name>.tags]] tag map and its
// [[devices.<name>.bundles]] tag bundles (the specs and the reader are in
// fiducial_driver.hpp), and the readers the tools use: a corner_calibration file, and
// the fiducial devices of a whole covtrackd config.
#include <map>
#include <string>
#include <vector>

#include "bundle_pose.hpp"
#include "corner_noise.hpp"
#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/fiducial/fiducial_driver.hpp"
#include "tag_detector.hpp"

namespace covtrack::fiducial {

struct FiducialConfig {
  std::string device;
  std::string parent_frame = "camera";  // poses are T_camera_tag
  std::string source;          // a V4L2 camera index ("0"), a video file or an image pattern
  std::string calibration;     // OpenCV calibration file
  std::string corner_calibration;  // this camera's corner model (covtrack calibrate-fiducial), if any
  DetectorOptions detector;
  CornerNoiseModel noise;
  double ambiguity_chi2 = 40;
  double rate_hz = 30;         // files: replay pace (0: as fast as possible); cameras: ignored
  bool loop = true;            // files: start over at the end
  bool publish_raw = true;
  bool publish_images = false;  // the frames themselves, for a see-through view of a log
  int image_every_n = 1;        // one image per this many frames
  int image_jpeg_quality = 80;
  std::map<int, double> tag_size_m;  // the tag map: id -> edge of the detected square
  std::vector<TagBundle> bundles;     // a tag is in one bundle at most, and then not in the map
  double bundle_consistency_chi2 = 40;
};

// The corner noise model's keys (corner_*), in a device's table or a corner_calibration file.
std::vector<KeySpec> corner_model_keys();
// Each corner_* key with the model's value it sets: one list for reading and writing them.
struct CornerModelField {
  const char* key;
  double CornerNoiseModel::*value;
};
const std::vector<CornerModelField>& corner_model_fields();
// A corner_calibration file's model; errors name the file, line and key.
Result<CornerNoiseModel> read_corner_calibration(const std::string& file);

// The tag bundles of every fiducial device in a covtrackd config file (for tools that
// render or calibrate a bundle as the daemon will see it); every problem of those
// devices' tables in one error.
Result<std::vector<TagBundle>> read_config_bundles(const std::string& config_file);
// One fiducial device of a covtrackd config file (for tools that calibrate it).
Result<FiducialConfig> read_config_device(const std::string& config_file, const std::string& device);

}  // namespace covtrack::fiducial
