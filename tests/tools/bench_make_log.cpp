// Writes a log of N small events (default 1,000,000) on 4 channels, 1 us apart, for
// bench_replay.sh. Usage: bench_make_log FILE [N]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "covtrack/lcmlog/log_writer.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE [N]\n", argv[0]);
    return 2;
  }
  const long count = argc > 2 ? std::atol(argv[2]) : 1'000'000;
  auto writer = covtrack::lcmlog::LogWriter::create(argv[1], true);
  if (!writer) {
    std::fprintf(stderr, "%s\n", writer.error().message.c_str());
    return 1;
  }
  const std::string channels[] = {"bench/a", "bench/b", "bench/c", "bench/d"};
  std::vector<std::byte> payload(64);
  for (long i = 0; i < count; ++i) {
    payload[0] = static_cast<std::byte>(i);
    if (!writer->write(1'700'000'000'000'000 + i, channels[i % 4], payload)) return 1;
  }
  return 0;
}
