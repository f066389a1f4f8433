#pragma once
// The AprilTag fiducial tracker: frames from a camera, a video or an image sequence;
// per mapped tag a pose T_camera_tag (sensor "tag<id>") with its covariance, per tag
// bundle one pose T_camera_bundle (sensor: the bundle's name) from all its tags in view;
// the raw detections on covtrack/raw/<device>.
//
// Its options (type = "fiducial"), read from the [devices.<name>] table, its
// [[devices.<name>.tags]] tag map, its [[devices.<name>.bundles]] tag bundles and a
// corner_calibration file. No USB ids: a camera is any V4L2 device, whatever its maker,
// so `covtrack devices` has none to look for.
//
// The options' struct is not part of this header: it holds the detector's options, the
// corner noise model and the bundles' geometry, which are the vision code's own types
// (src/fiducial_config.hpp). The daemon passes it from the reader to the factory unread.
#include <cstdint>
#include <memory>
#include <string>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"

namespace covtrack::fiducial {

struct FiducialConfig;

const TableSpec& fiducial_device_spec();
const TableSpec& fiducial_tag_spec();
const TableSpec& fiducial_bundle_spec();
const TableSpec& fiducial_bundle_tag_spec();
// The [corner_model] table of a file written by `covtrack calibrate-fiducial`.
const TableSpec& corner_calibration_spec();

// Relative paths are taken from the config file's folder. Problems go to the reader.
std::shared_ptr<const FiducialConfig> read_fiducial_config(TableReader& device, const std::string& device_name);

// A file source is paced, and every frame stamped, on `clock`.
std::unique_ptr<Driver> make_fiducial_driver(const FiducialConfig& config, std::uint64_t run_index,
                                             DriverClock& clock = real_clock());

}  // namespace covtrack::fiducial
