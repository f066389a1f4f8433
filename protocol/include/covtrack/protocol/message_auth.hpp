#pragma once
// Authenticated messages (docs/authentication.md): with a shared key, the daemon appends
// a trailer to each LCM-encoded message, after its last field, and a client that holds
// the key checks it. The message types stay as they are, so LCM tools, loggers and
// clients without the key read the message and ignore the trailer.
//
// Trailer, 60 bytes, big-endian as LCM encodes:
//   instance_id  u64  the sender's, random per start (a daemon's heartbeats name it too)
//   counter      u64  the sender's, +1 per message of any channel
//   sent_us      i64  the sender's clock (CLOCK_REALTIME, clock.hpp) when it signed
//   mac          32   keyed BLAKE2b-256 (libsodium crypto_generichash) of
//                     "covtrack-auth-1" NUL channel NUL message instance_id counter sent_us
//   magic        4    "CTA" and version 1
#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

inline constexpr std::size_t kAuthKeyBytes = 32;
inline constexpr std::size_t kAuthMacBytes = 32;
inline constexpr std::size_t kAuthTrailerBytes = 8 + 8 + 8 + kAuthMacBytes + 4;

struct AuthKey {
  std::array<unsigned char, kAuthKeyBytes> bytes{};
};

// A key file holds the key as 64 hexadecimal digits (a newline after them is allowed).
// It must be a regular file that others (not owner, not group) cannot read or write:
// otherwise it is refused, with what to do.
Result<AuthKey> load_auth_key(const std::string& path);
// A new random key, written to a new file (never over an existing one) with mode 0600.
Result<void> write_new_auth_key(const std::string& path);
// The environment variable clients read a key file's path from when no option names one.
inline constexpr const char* kKeyFileVariable = "COVTRACK_KEY_FILE";
// `option` if given, else $COVTRACK_KEY_FILE, else empty (no authentication).
std::string effective_key_file(const std::string& option);

struct AuthTrailer {
  std::uint64_t instance_id = 0;
  std::uint64_t counter = 0;
  std::int64_t sent_us = 0;
};

// Appends the trailer to `message` (an LCM-encoded message, to be sent on `channel`).
void append_auth_trailer(const AuthKey& key, std::string_view channel, const AuthTrailer& trailer,
                         std::vector<std::uint8_t>& message);

// Whether `tail`, what follows a message's last field, is a trailer (by its size and
// magic; nothing checks its MAC): decode_message() accepts a message followed by one.
bool is_auth_trailer(std::span<const std::byte> tail);

enum class AuthFault {
  Missing,  // no trailer
  Forged,   // a trailer whose MAC does not match: another key, or altered bytes
};
const char* to_string(AuthFault fault);

struct Authenticated {
  std::span<const std::byte> message;  // the bytes before the trailer
  AuthTrailer trailer;
};

// Checks the trailer of `bytes`, received on `channel`, against the key (in constant time).
std::expected<Authenticated, AuthFault> authenticate(const AuthKey& key, std::string_view channel,
                                                     std::span<const std::byte> bytes);

// Signs what one sender publishes: one instance id, one counter for all its channels.
// Not thread-safe: a sender signs under the lock that orders its messages.
class MessageSigner {
 public:
  MessageSigner(const AuthKey& key, std::uint64_t instance_id) : key_(key), instance_id_(instance_id) {}
  void sign(std::string_view channel, std::vector<std::uint8_t>& message);

 private:
  AuthKey key_;
  std::uint64_t instance_id_;
  std::uint64_t counter_ = 0;
};

}  // namespace covtrack
