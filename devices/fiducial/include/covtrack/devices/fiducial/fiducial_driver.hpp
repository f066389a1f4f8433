#pragma once
// The AprilTag fiducial tracker: frames from a camera, a video or an image sequence;
// per mapped tag a pose T_camera_tag (sensor "tag<id>") with its covariance, per tag
// bundle one pose T_camera_bundle (sensor: the bundle's name) from all its tags in view;
// the raw detections on covtrack/raw/<device>.
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/fiducial/fiducial_config.hpp"

namespace covtrack::fiducial {

// A file source is paced, and every frame stamped, on `clock`.
std::unique_ptr<Driver> make_fiducial_driver(const FiducialConfig& config, std::uint64_t run_index,
                                             DriverClock& clock = real_clock());

}  // namespace covtrack::fiducial
