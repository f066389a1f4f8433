#include "covtrack/vrpn/session.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "covtrack/vrpn/system_messages.hpp"

namespace covtrack::vrpn {
namespace {
// VRPN's tables hold this many senders and as many types: ids are below it. The limit
// also bounds what a hostile peer can make us keep.
constexpr std::int32_t kMaxIds = 2000;

std::optional<std::int32_t> index_of(const std::vector<std::string>& names, std::string_view name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) return std::nullopt;
  return static_cast<std::int32_t>(it - names.begin());
}
}  // namespace

Session::Session(std::vector<std::string> senders, std::vector<std::string> types)
    : senders_(std::move(senders)), types_(std::move(types)) {
  const Cookie cookie = make_cookie();
  output_.assign(cookie.begin(), cookie.end());
}

std::vector<std::uint8_t> Session::take_output() { return std::exchange(output_, {}); }

void Session::queue(const Message& m) { append_message(output_, m, tcp_sequence_++); }

void Session::describe_ourselves(std::int64_t now_us) {
  for (std::size_t i = 0; i < senders_.size(); ++i)
    queue({static_cast<std::int32_t>(i), kSenderDescription, now_us, name_description(senders_[i])});
  for (std::size_t i = 0; i < types_.size(); ++i)
    queue({static_cast<std::int32_t>(i), kTypeDescription, now_us, name_description(types_[i])});
}

Result<std::vector<NamedMessage>> Session::receive(std::span<const std::uint8_t> bytes, std::int64_t now_us) {
  input_.insert(input_.end(), bytes.begin(), bytes.end());
  std::size_t used = 0;
  if (!peer_) {
    if (input_.size() < kCookieSize) return std::vector<NamedMessage>{};
    auto cookie = check_cookie(std::span(input_).first(kCookieSize));
    if (!cookie) return std::unexpected(cookie.error());
    peer_ = *cookie;
    used = kCookieSize;
    describe_ourselves(now_us);
  }
  std::vector<NamedMessage> out;
  for (;;) {
    auto decoded = decode_message(std::span(input_).subspan(used));
    if (!decoded) return std::unexpected(decoded.error());
    if (!*decoded) break;
    used += (*decoded)->consumed;
    if (auto handled = handle(std::move((*decoded)->message), out); !handled)
      return std::unexpected(handled.error());
  }
  input_.erase(input_.begin(), input_.begin() + static_cast<std::ptrdiff_t>(used));
  return out;
}

Result<std::vector<NamedMessage>> Session::receive_datagram(std::span<const std::uint8_t> datagram) {
  if (!peer_) return fail("VRPN datagram before the handshake");
  auto messages = decode_datagram(datagram);
  if (!messages) return std::unexpected(messages.error());
  std::vector<NamedMessage> out;
  for (auto& m : *messages)
    if (auto handled = handle(std::move(m), out); !handled) return std::unexpected(handled.error());
  return out;
}

Result<void> Session::handle(Message m, std::vector<NamedMessage>& out) {
  if (m.type < 0) return handle_system(m);
  const auto type = peer_types_.find(m.type);
  const auto sender = peer_senders_.find(m.sender);
  if (type == peer_types_.end() || sender == peer_senders_.end()) {
    ++undescribed_;
    return {};
  }
  out.push_back({sender->second, type->second, m.time_us, std::move(m.payload)});
  return {};
}

Result<void> Session::handle_system(const Message& m) {
  switch (m.type) {
    case kSenderDescription:
    case kTypeDescription: {
      auto name = parse_name_description(m.payload);
      if (!name) return std::unexpected(name.error());
      auto& table = m.type == kSenderDescription ? peer_senders_ : peer_types_;
      if (m.sender < 0 || m.sender >= kMaxIds)
        return fail(fmt::format("VRPN description of id {} (VRPN's ids are 0-{})", m.sender, kMaxIds - 1));
      table[m.sender] = std::move(*name);
      return {};
    }
    case kUdpDescription: {
      auto host = parse_udp_description(m.payload);
      if (!host) return std::unexpected(host.error());
      if (m.sender < 1 || m.sender > 65535)
        return fail(fmt::format("VRPN UDP description names port {}", m.sender));
      peer_udp_ = UdpEndpoint{std::move(*host), m.sender};
      return {};
    }
    default:
      // A log request (covtrack logs nothing for a peer), a disconnect marker (only ever
      // in log files) or a system type this side has no handler for: VRPN skips those too.
      if (m.type <= -kMaxIds) return fail(fmt::format("VRPN system message type {} is out of range", m.type));
      return {};
  }
}

std::optional<Message> Session::local_message(std::string_view sender, std::string_view type, std::int64_t time_us,
                                              std::vector<std::uint8_t> payload) const {
  const auto s = index_of(senders_, sender);
  const auto t = index_of(types_, type);
  if (!peer_ || !s || !t) return std::nullopt;
  return Message{*s, *t, time_us, std::move(payload)};
}

bool Session::send(std::string_view sender, std::string_view type, std::int64_t time_us,
                   std::vector<std::uint8_t> payload) {
  const auto m = local_message(sender, type, time_us, std::move(payload));
  if (m) queue(*m);
  return m.has_value();
}

bool Session::describe_udp(std::string_view host, int port, std::int64_t time_us) {
  if (!peer_) return false;
  queue({static_cast<std::int32_t>(port), kUdpDescription, time_us, udp_description(host)});
  return true;
}

std::vector<std::uint8_t> Session::frame_for_udp(std::string_view sender, std::string_view type, std::int64_t time_us,
                                                 std::vector<std::uint8_t> payload) {
  std::vector<std::uint8_t> out;
  if (const auto m = local_message(sender, type, time_us, std::move(payload))) append_message(out, *m, udp_sequence_++);
  return out;
}

}  // namespace covtrack::vrpn
