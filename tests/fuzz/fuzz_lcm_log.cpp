// LCM log files: the reader over arbitrary file contents (through a real file, since it
// maps one), and each event's message checked the way record and replay check them.
#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/channel_messages.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;
using namespace covtrack::lcmlog;

namespace {

struct Pass {
  std::uint64_t events = 0, event_bytes = 0, damaged_bytes = 0;
};

Pass read_all(LogReader& reader) {
  Pass pass;
  std::uint64_t last_end = 0;
  while (const auto event = reader.next()) {
    FUZZ_CHECK(event->offset >= last_end);
    FUZZ_CHECK(!event->channel.empty() && event->channel.size() <= std::size_t(kMaxChannelLength));
    last_end = event->offset + kEventHeaderBytes + event->channel.size() + event->payload.size();
    FUZZ_CHECK(last_end <= reader.size() && reader.offset() == last_end);
    ++pass.events;
    pass.event_bytes += last_end - event->offset;
    if (const auto rejection = check_channel_message(event->channel, event->payload))
      FUZZ_CHECK(!rejection->describe().empty());
  }
  for (const LogDamage& d : reader.damage()) {
    FUZZ_CHECK(d.offset + d.skipped_bytes <= reader.size());
    FUZZ_CHECK(!describe(d).empty());
    pass.damaged_bytes += d.skipped_bytes;
  }
  return pass;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::ScratchFile file(".lcm");
  auto reader = LogReader::open(file.write({data, size}));
  FUZZ_CHECK(reader.has_value());
  FUZZ_CHECK(reader->size() == size);
  const Pass first = read_all(*reader);
  // Every byte is in a good event or in a damaged range, never both, never neither.
  FUZZ_CHECK(first.event_bytes + first.damaged_bytes == size);
  reader->rewind();
  const Pass second = read_all(*reader);
  FUZZ_CHECK(second.events == first.events && second.damaged_bytes == first.damaged_bytes);
  return 0;
}
