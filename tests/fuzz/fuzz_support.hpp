#pragma once
// What the harnesses share: a failed invariant ends the run like a crash (libFuzzer keeps
// the input), input split into the chunks a serial read would deliver, and a scratch file
// for readers that take a path.
//
// No harness catches an exception: an exception escaping a decoder is a bug (the readers
// report bad input through Result / std::expected), and libFuzzer treats the resulting
// std::terminate as a crash.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <string_view>

namespace covtrack::fuzz {

[[noreturn]] inline void invariant_failed(const char* what, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: fuzz invariant broken: %s\n", file, line, what);
  std::abort();
}

#define FUZZ_CHECK(condition) \
  ((condition) ? void(0) : ::covtrack::fuzz::invariant_failed(#condition, __FILE__, __LINE__))

inline bool finite(double v) { return std::isfinite(v); }

// Reads the input front to back: a few leading bytes choose options, the rest is data.
class Input {
 public:
  explicit Input(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::uint8_t byte() {
    if (bytes_.empty()) return 0;
    const std::uint8_t b = bytes_.front();
    bytes_ = bytes_.subspan(1);
    return b;
  }
  std::span<const std::uint8_t> rest() const { return bytes_; }
  std::string_view rest_text() const {
    return {reinterpret_cast<const char*>(bytes_.data()), bytes_.size()};
  }

 private:
  std::span<const std::uint8_t> bytes_;
};

// Calls feed(chunk) over `data` in chunks of 1 to `max_chunk` bytes, their sizes drawn
// from `seed` (the same input always gives the same chunks): a decoder must give the same
// frames however a read splits the stream.
template <typename Feed>
void feed_in_chunks(std::span<const std::uint8_t> data, std::uint8_t seed, std::size_t max_chunk, Feed feed) {
  std::uint32_t state = seed * 2654435761u + 1;
  while (!data.empty()) {
    state = state * 1103515245u + 12345u;
    const std::size_t n = std::min<std::size_t>(data.size(), 1 + (state >> 16) % max_chunk);
    feed(data.first(n));
    data = data.subspan(n);
  }
}

// A file of this process's own, rewritten for each input: in /dev/shm when there is one
// (rewriting a file on disk cost 2.4 ms an input, 100 times more than in memory), else
// in $TMPDIR or /tmp.
class ScratchFile {
 public:
  explicit ScratchFile(const char* suffix) {
    const char* tmpdir = std::getenv("TMPDIR");
    const std::string dir = ::access("/dev/shm", W_OK) == 0 ? "/dev/shm" : tmpdir && *tmpdir ? tmpdir : "/tmp";
    path_ = dir + "/covtrack_fuzz_XXXXXX" + suffix;
    const int fd = ::mkstemps(path_.data(), static_cast<int>(std::string_view(suffix).size()));
    if (fd < 0) invariant_failed("cannot create a scratch file", __FILE__, __LINE__);
    ::close(fd);
  }
  ~ScratchFile() { ::unlink(path_.c_str()); }
  const std::string& write(std::span<const std::uint8_t> bytes) {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    if (!f || std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0)
      invariant_failed("cannot write the scratch file", __FILE__, __LINE__);
    return path_;
  }

 private:
  std::string path_;
};

}  // namespace covtrack::fuzz
