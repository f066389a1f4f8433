// XpressNet (Lenz): the frame decoder over arbitrary serial bytes, in arbitrary read
// chunks, then the meaning of each frame as a reply and as a request.
#include <variant>

#include "fuzz/fuzz_support.hpp"
#include "xpressnet_framing.hpp"
#include "xpressnet_messages.hpp"

using namespace covtrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input input({data, size});
  const std::uint8_t chunking = input.byte();
  lenz::FrameDecoder decoder;
  std::uint64_t frames = 0;
  fuzz::feed_in_chunks(input.rest(), chunking, 24, [&](std::span<const std::uint8_t> chunk) {
    for (const lenz::Frame& frame : decoder.push(chunk)) {
      ++frames;
      // A frame is its header and as many data bytes as the header's low nibble says.
      FUZZ_CHECK(frame.bytes.size() == std::size_t(frame.header() & 0x0F) + 1u);
      // Encoding it again and decoding that gives the same frame.
      lenz::FrameDecoder again;
      const auto copy = again.push(lenz::encode_frame(frame.bytes, frame.prefix));
      FUZZ_CHECK(copy.size() == 1 && copy[0].bytes == frame.bytes && copy[0].prefix == frame.prefix);
      const lenz::Reply reply = lenz::interpret_reply(frame);
      if (const auto* notice = std::get_if<lenz::InterfaceNotice>(&reply))
        FUZZ_CHECK(!lenz::describe_notice(notice->code).empty());
      FUZZ_CHECK(!lenz::reply_bytes(reply).empty());
      FUZZ_CHECK(!lenz::request_bytes(lenz::interpret_request(frame)).empty());
    }
  });
  FUZZ_CHECK(decoder.counters().frames == frames);
  FUZZ_CHECK(decoder.counters().skipped_bytes <= size);
  return 0;
}
