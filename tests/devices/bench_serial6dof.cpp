// Cost of decoding a serial 6-DOF stream that starts with a long run of line noise and
// then carries valid records, for each of the three decoders. Getting back in step must
// cost time linear in the noise: compare 4 KiB with 64 KiB of noise (x16 bytes should
// take about x16 time), fed in 4 KiB reads (the driver's read size) and in one piece.
// Run: taskset -c 0 build/tests/devices/bench_serial6dof
#include <algorithm>
#include <span>

#include <benchmark/benchmark.h>

#include "serial6dof_stream.hpp"

using namespace covtrack::serial6dof;

namespace {

constexpr int kRecords = 200;

template <typename Decoder, typename Encode>
void run(benchmark::State& state, Decoder make_decoder, Encode encode) {
  const auto noise = static_cast<std::size_t>(state.range(0));
  const auto chunk = static_cast<std::size_t>(state.range(1));
  Bytes stream = test::noise_without_records(noise);
  for (int i = 0; i < kRecords; ++i) {
    const Bytes r = encode(test::stream_record(i));
    stream.insert(stream.end(), r.begin(), r.end());
  }
  for (auto _ : state) {
    auto decoder = make_decoder();
    std::size_t items = 0;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      const std::size_t n = std::min(chunk, stream.size() - at);
      items += decoder.feed(std::span(stream).subspan(at, n)).size();
    }
    if (items != kRecords) state.SkipWithError("records lost: the stream is not what it should be");
    benchmark::DoNotOptimize(items);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
}

void BM_Fastrak(benchmark::State& state) {
  const FastrakFormat f{Units::Centimetres, {FastrakExtra::Timestamp}, true};
  run(state, [&] { return FastrakDecoder(f); }, [&](const TrackerRecord& r) { return encode_fastrak_record(r, f); });
}

void BM_Liberty(benchmark::State& state) {
  const LibertyFormat f{Units::Centimetres, {LibertyExtra::Timestamp}};
  run(state, [&] { return LibertyDecoder(f); }, [&](const TrackerRecord& r) { return encode_liberty_record(r, f); });
}

void BM_Flock(benchmark::State& state) {
  const FlockFormat f{36, true, 1};
  run(state, [&] { return FlockDecoder(f); }, [&](const TrackerRecord& r) { return encode_flock_record(r, f); });
}

// Arguments: bytes of noise, bytes per feed (1 MiB: the whole stream at once).
void noise_and_chunks(benchmark::internal::Benchmark* b) {
  for (long noise : {4096L, 65536L, 262144L})
    for (long chunk : {4096L, 1L << 20}) b->Args({noise, chunk});
  b->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Fastrak)->Apply(noise_and_chunks);
BENCHMARK(BM_Liberty)->Apply(noise_and_chunks);
BENCHMARK(BM_Flock)->Apply(noise_and_chunks);

}  // namespace

BENCHMARK_MAIN();
