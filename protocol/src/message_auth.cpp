#include "covtrack/protocol/message_auth.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include <fmt/format.h>

#include "covtrack/protocol/clock.hpp"

namespace covtrack {
namespace {

constexpr std::array<unsigned char, 4> kMagic = {'C', 'T', 'A', 1};
// Separates this use of the key from any other a future version may make of it.
constexpr std::string_view kDomain = "covtrack-auth-1";
constexpr std::size_t kHexDigits = 2 * kAuthKeyBytes;
constexpr std::size_t kFieldsBytes = 24;  // instance_id, counter, sent_us

// sodium_init() is safe to call again and from several threads; it must precede randombytes.
bool sodium_ready() {
  static const bool ready = sodium_init() >= 0;
  return ready;
}

void put_u64(unsigned char* out, std::uint64_t v) {
  for (int i = 7; i >= 0; --i, v >>= 8) out[i] = static_cast<unsigned char>(v & 0xff);
}
std::uint64_t get_u64(const unsigned char* in) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | in[i];
  return v;
}

std::array<unsigned char, kAuthMacBytes> mac_of(const AuthKey& key, std::string_view channel,
                                                std::span<const unsigned char> message,
                                                const unsigned char* fields) {
  sodium_ready();  // picks the fastest BLAKE2b for this CPU, once
  crypto_generichash_state state;
  crypto_generichash_init(&state, key.bytes.data(), key.bytes.size(), kAuthMacBytes);
  const unsigned char nul = 0;
  crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(kDomain.data()), kDomain.size());
  crypto_generichash_update(&state, &nul, 1);
  crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(channel.data()), channel.size());
  crypto_generichash_update(&state, &nul, 1);
  crypto_generichash_update(&state, message.data(), message.size());
  crypto_generichash_update(&state, fields, kFieldsBytes);
  std::array<unsigned char, kAuthMacBytes> mac;
  crypto_generichash_final(&state, mac.data(), mac.size());
  return mac;
}

}  // namespace

const char* to_string(AuthFault fault) {
  switch (fault) {
    case AuthFault::Missing: return "unauthenticated";
    case AuthFault::Forged: return "forged";
  }
  return "?";
}

Result<AuthKey> load_auth_key(const std::string& path) {
  // O_NONBLOCK: a FIFO named by mistake must not block the open; it is refused below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) return fail(fmt::format("key file {}: {}", path, std::strerror(errno)));
  struct stat st {};
  char text[kHexDigits + 3] = {};
  ssize_t n = -1;
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) n = ::read(fd, text, sizeof text - 1);
  ::close(fd);
  if (!S_ISREG(st.st_mode)) return fail(fmt::format("key file {}: not a regular file", path));
  if (st.st_mode & S_IRWXO)
    return fail(fmt::format("key file {}: others may read or write it (mode {:04o}); a shared key must stay "
                            "secret: chmod o-rwx {}", path, st.st_mode & 07777, path));
  if (n < 0) return fail(fmt::format("key file {}: {}", path, std::strerror(errno)));
  std::string_view body(text, static_cast<std::size_t>(n));
  if (body.ends_with('\n')) body.remove_suffix(1);
  AuthKey key;
  std::size_t decoded = 0;
  if (body.size() != kHexDigits ||
      sodium_hex2bin(key.bytes.data(), key.bytes.size(), body.data(), body.size(), nullptr, &decoded, nullptr) != 0 ||
      decoded != kAuthKeyBytes)
    return fail(fmt::format("key file {}: expected {} hexadecimal digits (a key made by `covtrack keygen`)", path,
                            kHexDigits));
  return key;
}

Result<void> write_new_auth_key(const std::string& path) {
  if (!sodium_ready()) return fail("libsodium failed to initialise");
  AuthKey key;
  randombytes_buf(key.bytes.data(), key.bytes.size());
  char hex[kHexDigits + 1];
  sodium_bin2hex(hex, sizeof hex, key.bytes.data(), key.bytes.size());
  const std::string text = std::string(hex) + "\n";
  sodium_memzero(key.bytes.data(), key.bytes.size());
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0)
    return fail(fmt::format("{}: {}{}", path, std::strerror(errno),
                            errno == EEXIST ? " (a key file is never overwritten: remove it first)" : ""));
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const bool closed = ::close(fd) == 0;
  if (!written || !closed) {
    ::unlink(path.c_str());
    return fail(fmt::format("{}: writing the key failed", path));
  }
  return {};
}

std::string effective_key_file(const std::string& option) {
  if (!option.empty()) return option;
  const char* from_env = std::getenv(kKeyFileVariable);
  return from_env ? from_env : "";
}

void append_auth_trailer(const AuthKey& key, std::string_view channel, const AuthTrailer& trailer,
                         std::vector<std::uint8_t>& message) {
  const std::size_t size = message.size();
  message.resize(size + kAuthTrailerBytes);
  unsigned char* t = message.data() + size;
  put_u64(t, trailer.instance_id);
  put_u64(t + 8, trailer.counter);
  put_u64(t + 16, static_cast<std::uint64_t>(trailer.sent_us));
  const auto mac = mac_of(key, channel, {message.data(), size}, t);
  std::memcpy(t + kFieldsBytes, mac.data(), mac.size());
  std::memcpy(t + kFieldsBytes + kAuthMacBytes, kMagic.data(), kMagic.size());
}

bool is_auth_trailer(std::span<const std::byte> tail) {
  return tail.size() == kAuthTrailerBytes &&
         std::memcmp(tail.data() + kAuthTrailerBytes - kMagic.size(), kMagic.data(), kMagic.size()) == 0;
}

std::expected<Authenticated, AuthFault> authenticate(const AuthKey& key, std::string_view channel,
                                                     std::span<const std::byte> bytes) {
  if (bytes.size() < kAuthTrailerBytes || !is_auth_trailer(bytes.last(kAuthTrailerBytes)))
    return std::unexpected(AuthFault::Missing);
  const std::size_t size = bytes.size() - kAuthTrailerBytes;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const unsigned char* t = data + size;
  const auto mac = mac_of(key, channel, {data, size}, t);
  if (sodium_memcmp(mac.data(), t + kFieldsBytes, kAuthMacBytes) != 0) return std::unexpected(AuthFault::Forged);
  return Authenticated{bytes.first(size),
                       {get_u64(t), get_u64(t + 8), static_cast<std::int64_t>(get_u64(t + 16))}};
}

void MessageSigner::sign(std::string_view channel, std::vector<std::uint8_t>& message) {
  append_auth_trailer(key_, channel, {instance_id_, ++counter_, now_us()}, message);
}

}  // namespace covtrack
