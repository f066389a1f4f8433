#include "xpressnet_messages.hpp"

#include <fmt/format.h>

#include "overloaded.hpp"

namespace covtrack::lenz {
namespace {

std::uint8_t header(std::uint8_t opcode, std::size_t data_bytes) {
  return static_cast<std::uint8_t>(opcode | (data_bytes & 0x0F));
}

}  // namespace

Reply interpret_reply(const Frame& f) {
  const auto& b = f.bytes;
  const std::size_t n = b.size() - 1;  // data bytes
  const std::uint8_t h = b[0];
  if (f.opcode() == 0x40 && n >= 2 && n % 2 == 0) {
    Feedback fb;
    for (std::size_t i = 1; i + 1 < b.size(); i += 2) fb.pairs.push_back({b[i], b[i + 1]});
    return fb;
  }
  if (h == 0x01 && n == 1) return InterfaceNotice{b[1]};
  if (h == 0x02 && n == 2) return InterfaceVersion{b[1], b[2]};
  if (h == 0x63 && n == 3 && b[1] == 0x21) return CommandStationVersion{b[2], b[3]};
  if (h == 0x62 && n == 2 && b[1] == 0x21) return CommandStationVersion{b[2], -1};
  if (h == 0x62 && n == 2 && b[1] == 0x22) return CommandStationStatus{b[2]};
  if (h == 0xF2 && n == 2) return InterfaceSetting{b[1], b[2]};
  if (h == 0x61 && n == 1) {
    switch (b[1]) {
      case 0x00: return Broadcast{BroadcastKind::TrackPowerOff};
      case 0x01: return Broadcast{BroadcastKind::TrackPowerOn};
      case 0x02: return Broadcast{BroadcastKind::ServiceMode};
      case 0x80: return Broadcast{BroadcastKind::TransferError};
      case 0x81: return Broadcast{BroadcastKind::CommandStationBusy};
      case 0x82: return Broadcast{BroadcastKind::NotSupported};
      default: break;
    }
  }
  if (h == 0x81 && n == 1 && b[1] == 0x00) return Broadcast{BroadcastKind::EmergencyStop};
  return UnknownReply{b};
}

std::string describe_notice(std::uint8_t code) {
  switch (code) {
    case 0x01: return "interface: error between PC and interface";
    case 0x02: return "interface: error between interface and command station";
    case 0x03: return "interface: unknown communication error";
    case 0x04: return "interface: OK, command forwarded";
    case 0x05: return "interface: command station no longer provides a timeslot";
    case 0x06: return "interface: buffer overflow";
    case 0x07: return "interface: timeslot restored";
    case 0x08: return "interface: request sent while no timeslot";
    case 0x09: return "interface: bad data in request";
    case 0x0A: return "interface: retransmit request";
    default: return fmt::format("interface: unknown notice 0x{:02X}", code);
  }
}

Request interpret_request(const Frame& f) {
  const auto& b = f.bytes;
  const std::size_t n = b.size() - 1;
  const std::uint8_t h = b[0];
  if (h == 0xF0 && n == 0) return InterfaceVersionRequest{};
  if (h == 0x21 && n == 1 && b[1] == 0x21) return CommandStationVersionRequest{};
  if (h == 0x21 && n == 1 && b[1] == 0x24) return CommandStationStatusRequest{};
  if (h == 0x21 && n == 1 && (b[1] == 0x80 || b[1] == 0x81)) return TrackPowerRequest{b[1] == 0x81};
  if (h == 0x80 && n == 0) return EmergencyStopRequest{};
  if (h == 0x42 && n == 2 && (b[2] & 0xFE) == 0x80) return FeedbackRequest{b[1], (b[2] & 0x01) != 0};
  if (h == 0xF2 && n == 2) return InterfaceSettingRequest{b[1], b[2]};
  return UnknownRequest{b};
}

std::vector<std::uint8_t> request_bytes(const Request& request) {
  return std::visit(
      overloaded{
          [](const InterfaceVersionRequest&) { return std::vector<std::uint8_t>{0xF0}; },
          [](const CommandStationVersionRequest&) { return std::vector<std::uint8_t>{0x21, 0x21}; },
          [](const CommandStationStatusRequest&) { return std::vector<std::uint8_t>{0x21, 0x24}; },
          [](const FeedbackRequest& r) {
            return std::vector<std::uint8_t>{0x42, r.address, static_cast<std::uint8_t>(0x80 | (r.upper_nibble ? 1 : 0))};
          },
          [](const InterfaceSettingRequest& r) { return std::vector<std::uint8_t>{0xF2, r.which, r.value}; },
          [](const TrackPowerRequest& r) {
            return std::vector<std::uint8_t>{0x21, static_cast<std::uint8_t>(r.on ? 0x81 : 0x80)};
          },
          [](const EmergencyStopRequest&) { return std::vector<std::uint8_t>{0x80}; },
          [](const UnknownRequest& r) { return r.bytes; },
      },
      request);
}

std::vector<std::uint8_t> reply_bytes(const Reply& reply) {
  return std::visit(
      overloaded{
          [](const Feedback& fb) {
            std::vector<std::uint8_t> out{header(0x40, fb.pairs.size() * 2)};
            for (const auto& p : fb.pairs) {
              out.push_back(p.address);
              out.push_back(p.data);
            }
            return out;
          },
          [](const InterfaceVersion& v) {
            return std::vector<std::uint8_t>{0x02, static_cast<std::uint8_t>(v.hardware_bcd),
                                             static_cast<std::uint8_t>(v.software_bcd)};
          },
          [](const CommandStationVersion& v) {
            if (v.type < 0) return std::vector<std::uint8_t>{0x62, 0x21, static_cast<std::uint8_t>(v.version_bcd)};
            return std::vector<std::uint8_t>{0x63, 0x21, static_cast<std::uint8_t>(v.version_bcd),
                                             static_cast<std::uint8_t>(v.type)};
          },
          [](const CommandStationStatus& s) { return std::vector<std::uint8_t>{0x62, 0x22, s.bits}; },
          [](const InterfaceNotice& n) { return std::vector<std::uint8_t>{0x01, n.code}; },
          [](const InterfaceSetting& s) { return std::vector<std::uint8_t>{0xF2, s.which, s.value}; },
          [](const Broadcast& b) {
            switch (b.kind) {
              case BroadcastKind::TrackPowerOff: return std::vector<std::uint8_t>{0x61, 0x00};
              case BroadcastKind::TrackPowerOn: return std::vector<std::uint8_t>{0x61, 0x01};
              case BroadcastKind::ServiceMode: return std::vector<std::uint8_t>{0x61, 0x02};
              case BroadcastKind::TransferError: return std::vector<std::uint8_t>{0x61, 0x80};
              case BroadcastKind::CommandStationBusy: return std::vector<std::uint8_t>{0x61, 0x81};
              case BroadcastKind::NotSupported: return std::vector<std::uint8_t>{0x61, 0x82};
              case BroadcastKind::EmergencyStop: return std::vector<std::uint8_t>{0x81, 0x00};
            }
            return std::vector<std::uint8_t>{};
          },
          [](const UnknownReply& u) { return u.bytes; },
      },
      reply);
}

}  // namespace covtrack::lenz
