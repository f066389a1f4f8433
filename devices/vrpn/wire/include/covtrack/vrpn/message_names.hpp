#pragma once
// The message type names covtrack sends and reads, as VRPN's classes register them
// (docs/vrpn.md, "Names").
#include <string_view>

namespace covtrack::vrpn {

// vrpn_Tracker: one sensor's position and orientation.
inline constexpr std::string_view kTrackerPosQuat = "vrpn_Tracker Pos_Quat";
// vrpn_BaseClass: a client asks each second whether the device is there (empty
// payload, its sender the device's name); the server answers with a pong.
inline constexpr std::string_view kPing = "vrpn_Base ping_message";
inline constexpr std::string_view kPong = "vrpn_Base pong_message";

// The server a name like "Tracker0@host" reaches listens here unless given ":port".
inline constexpr int kDefaultPort = 3883;

}  // namespace covtrack::vrpn
