#pragma once
// One VRPN connection's protocol state, without any I/O (docs/vrpn.md, "Handshake"):
// bytes received go in, messages by name come out, and bytes to send wait in a buffer.
// Both sides send a cookie first; once the peer's cookie checks, each side describes
// the names behind its sender and type ids, and from then on a message's ids are
// mapped to names through the peer's descriptions. The daemon's VRPN server and the
// vrpn driver both use it.
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/result.hpp"
#include "covtrack/vrpn/cookie.hpp"
#include "covtrack/vrpn/framing.hpp"

namespace covtrack::vrpn {

// A user message from the peer, with the names its ids stand for.
struct NamedMessage {
  std::string sender;
  std::string type;
  std::int64_t time_us = 0;
  std::vector<std::uint8_t> payload;
};

// Where the peer takes UDP: the host it described and the port in the sender field.
struct UdpEndpoint {
  std::string host;
  int port = 0;
};

class Session {
 public:
  // The names this side sends with; an id is the name's index. Each must be a valid
  // VRPN name (is_valid_vrpn_name).
  Session(std::vector<std::string> senders, std::vector<std::string> types);

  // Bytes to send on TCP, in order (the cookie first), taken out of the session.
  std::vector<std::uint8_t> take_output();
  bool has_output() const { return !output_.empty(); }

  // Bytes received on TCP: the user messages completed by them. An error ends the
  // connection: a cookie of no VRPN 07 peer, a malformed header or system message.
  Result<std::vector<NamedMessage>> receive(std::span<const std::uint8_t> bytes, std::int64_t now_us);
  // One UDP datagram from the peer (VRPN sends time-critical messages that way).
  Result<std::vector<NamedMessage>> receive_datagram(std::span<const std::uint8_t> datagram);

  // The peer's cookie has arrived and checked; until then nothing but the cookie is sent.
  bool ready() const { return peer_.has_value(); }
  const std::optional<PeerCookie>& peer() const { return peer_; }
  const std::optional<UdpEndpoint>& peer_udp() const { return peer_udp_; }
  // Messages with an id the peer never described: dropped, as VRPN drops them.
  std::uint64_t undescribed() const { return undescribed_; }

  // Queues a message for TCP. False (nothing queued) before ready(), as VRPN discards
  // messages before the handshake, or for a sender or type not given at construction.
  bool send(std::string_view sender, std::string_view type, std::int64_t time_us,
            std::vector<std::uint8_t> payload);
  // Queues a UDP description: the peer is to send its time-critical messages (tracker
  // reports) to `host`:`port` (VRPN's clients send one after the handshake unless they
  // connected over TCP only). False before ready().
  bool describe_udp(std::string_view host, int port, std::int64_t time_us);
  // The same message framed on its own for a UDP datagram; empty when send() would refuse.
  std::vector<std::uint8_t> frame_for_udp(std::string_view sender, std::string_view type, std::int64_t time_us,
                                          std::vector<std::uint8_t> payload);

 private:
  std::optional<Message> local_message(std::string_view sender, std::string_view type, std::int64_t time_us,
                                       std::vector<std::uint8_t> payload) const;
  void queue(const Message& m);
  void describe_ourselves(std::int64_t now_us);
  Result<void> handle(Message m, std::vector<NamedMessage>& out);
  Result<void> handle_system(const Message& m);

  std::vector<std::string> senders_, types_;
  std::vector<std::uint8_t> output_, input_;
  std::uint32_t tcp_sequence_ = 0, udp_sequence_ = 0;
  std::optional<PeerCookie> peer_;
  std::map<std::int32_t, std::string> peer_senders_, peer_types_;
  std::optional<UdpEndpoint> peer_udp_;
  std::uint64_t undescribed_ = 0;
};

}  // namespace covtrack::vrpn
