// The cost of authentication per pose message against encoding and decoding it:
// sign (the daemon), verify and the replay check (a client with the key), beside LCM's
// encode and covtrack's checked decode of the same message; and HMAC-SHA-512-256
// (libsodium crypto_auth), the other MAC libsodium offers, over the same bytes.
// Run by hand: build/tests/protocol/bench_message_auth (docs/authentication.md, "Cost").
#include <benchmark/benchmark.h>
#include <sodium.h>

#include <vector>

#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/message_auth.hpp"
#include "covtrack/protocol/replay_guard.hpp"
#include "covtrack/protocol/wire_decode.hpp"
#include "client/pose_messages.hpp"

using namespace covtrack;

namespace {

const std::string kChannel = "covtrack/pose/optical/head";

pose_cov_t pose() { return test::pose_message("optical", "head", 1); }

std::vector<std::uint8_t> encoded() { return test::encoded(pose()); }

AuthKey key() {
  AuthKey k;
  for (std::size_t i = 0; i < k.bytes.size(); ++i) k.bytes[i] = static_cast<unsigned char>(i * 7 + 1);
  return k;
}

void BM_Encode(benchmark::State& state) {
  const pose_cov_t m = pose();
  std::vector<std::uint8_t> buffer;
  for (auto _ : state) {
    buffer.resize(static_cast<std::size_t>(m.getEncodedSize()));
    benchmark::DoNotOptimize(m.encode(buffer.data(), 0, static_cast<int>(buffer.size())));
  }
  state.counters["bytes"] = static_cast<double>(buffer.size());
}

void BM_DecodeChecked(benchmark::State& state) {
  const auto bytes = encoded();
  for (auto _ : state) benchmark::DoNotOptimize(decode_message<pose_cov_t>(bytes_of(bytes.data(), bytes.size())));
}

void BM_Sign(benchmark::State& state) {
  MessageSigner signer(key(), 1);
  const auto plain = encoded();
  std::vector<std::uint8_t> message;
  message.reserve(plain.size() + kAuthTrailerBytes);
  for (auto _ : state) {
    message.assign(plain.begin(), plain.end());
    signer.sign(kChannel, message);
    benchmark::DoNotOptimize(message.data());
  }
}

void BM_Verify(benchmark::State& state) {
  auto message = encoded();
  MessageSigner(key(), 1).sign(kChannel, message);
  const AuthKey k = key();
  for (auto _ : state) benchmark::DoNotOptimize(authenticate(k, kChannel, bytes_of(message.data(), message.size())));
}

// What a keyed client does per message before decoding: verify, then the replay check.
void BM_VerifyAndReplayCheck(benchmark::State& state) {
  const auto plain = encoded();
  MessageSigner signer(key(), 1);
  std::vector<std::vector<std::uint8_t>> messages(4096, plain);
  for (auto& m : messages) signer.sign(kChannel, m);
  const AuthKey k = key();
  ReplayGuard guard(3600);
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& m = messages[i++ % messages.size()];
    const auto checked = authenticate(k, kChannel, bytes_of(m.data(), m.size()));
    benchmark::DoNotOptimize(guard.check(kChannel, checked->trailer, now_us()));
  }
}

void BM_HmacSha512_256(benchmark::State& state) {
  if (sodium_init() < 0) state.SkipWithError("sodium_init failed");
  const auto plain = encoded();
  const AuthKey k = key();
  unsigned char mac[crypto_auth_BYTES];
  for (auto _ : state) {
    crypto_auth(mac, plain.data(), plain.size(), k.bytes.data());
    benchmark::DoNotOptimize(mac);
  }
}

BENCHMARK(BM_Encode);
BENCHMARK(BM_DecodeChecked);
BENCHMARK(BM_Sign);
BENCHMARK(BM_Verify);
BENCHMARK(BM_VerifyAndReplayCheck);
BENCHMARK(BM_HmacSha512_256);

}  // namespace

BENCHMARK_MAIN();
