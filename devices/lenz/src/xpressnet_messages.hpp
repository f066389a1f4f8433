#pragma once
// The meaning of XpressNet frames: what the interface and command station send to the
// PC (replies and broadcasts), what the PC sends (requests), and builders for both.
// Pure functions over frames (docs/xpressnet.md).
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "xpressnet_framing.hpp"

namespace covtrack::lenz {

// ---- interface / command station -> PC -------------------------------------------

// One address/data pair of a feedback broadcast or accessory-information reply (0x4N).
struct FeedbackPair {
  std::uint8_t address = 0;  // wire address: RS-bus module address - 1 (or turnout group)
  std::uint8_t data = 0;     // I TT N Z3..Z0
  int type() const { return (data >> 5) & 0x03; }  // 2 = feedback module
  bool is_feedback_module() const { return type() == 2; }
  bool upper_nibble() const { return (data & 0x10) != 0; }  // inputs 5-8 instead of 1-4
  std::uint8_t inputs() const { return data & 0x0F; }       // bit b = input b+1 (or b+5)
};
struct Feedback { std::vector<FeedbackPair> pairs; };

struct InterfaceVersion { int hardware_bcd = 0; int software_bcd = 0; };     // 02 HW SW
struct CommandStationVersion { int version_bcd = 0; int type = -1; };      // 63 21 VV TT; 62 21 VV (type -1)
struct CommandStationStatus { std::uint8_t bits = 0; };                     // 62 22 SS
struct InterfaceNotice { std::uint8_t code = 0; };                          // 01 CC: errors, OK, timeslot
struct InterfaceSetting { std::uint8_t which = 0; std::uint8_t value = 0; };  // F2 01 AA / F2 02 BB
enum class BroadcastKind : std::uint8_t {
  TrackPowerOff,    // 61 00
  TrackPowerOn,     // 61 01
  ServiceMode,      // 61 02
  TransferError,    // 61 80
  CommandStationBusy,  // 61 81
  NotSupported,     // 61 82
  EmergencyStop,    // 81 00
};
struct Broadcast { BroadcastKind kind; };
struct UnknownReply { std::vector<std::uint8_t> bytes; };

using Reply = std::variant<Feedback, InterfaceVersion, CommandStationVersion, CommandStationStatus,
                           InterfaceNotice, InterfaceSetting, Broadcast, UnknownReply>;

Reply interpret_reply(const Frame& frame);
// One line for logs and the daemon's last_error, e.g. "interface: buffer overflow".
std::string describe_notice(std::uint8_t code);

// Status bits of CommandStationStatus.
inline constexpr std::uint8_t kStatusEmergencyOff = 0x01;
inline constexpr std::uint8_t kStatusEmergencyStop = 0x02;
inline constexpr std::uint8_t kStatusServiceMode = 0x08;

// ---- PC -> interface / command station -------------------------------------------

struct InterfaceVersionRequest {};                       // F0
struct CommandStationVersionRequest {};                  // 21 21
struct CommandStationStatusRequest {};                   // 21 24
struct FeedbackRequest { std::uint8_t address = 0; bool upper_nibble = false; };  // 42 AA 8N
struct InterfaceSettingRequest { std::uint8_t which = 0; std::uint8_t value = 0; };  // F2 01 / F2 02
struct TrackPowerRequest { bool on = false; };           // 21 81 / 21 80
struct EmergencyStopRequest {};                          // 80
struct UnknownRequest { std::vector<std::uint8_t> bytes; };

using Request = std::variant<InterfaceVersionRequest, CommandStationVersionRequest,
                             CommandStationStatusRequest, FeedbackRequest, InterfaceSettingRequest,
                             TrackPowerRequest, EmergencyStopRequest, UnknownRequest>;

Request interpret_request(const Frame& frame);

// Header and data bytes (no XOR) of each request; encode_frame adds XOR and prefix.
std::vector<std::uint8_t> request_bytes(const Request& request);
// Header and data bytes of each reply or broadcast, as an interface would send them.
std::vector<std::uint8_t> reply_bytes(const Reply& reply);

}  // namespace covtrack::lenz
