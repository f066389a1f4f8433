#pragma once
// The client's names for the camera model, which lives in the bottom layer
// (covtrack/protocol/camera.hpp) so that the devices use the same one. The client's headers
// include this, so client::Camera, client::Vec2 and `using namespace covtrack::client`
// keep working as before the move.
#include "covtrack/protocol/camera.hpp"

namespace covtrack::client {

using covtrack::Camera;
using covtrack::load_camera;
using covtrack::Mat2;
using covtrack::Mat23;
using covtrack::save_camera;
using covtrack::Vec2;

}  // namespace covtrack::client
