// Polhemus LIBERTY / PATRIOT binary frames: the first byte picks the output format
// (units, extra items), the rest is the serial stream.
#include "fuzz/serial6dof_checks.hpp"
#include "liberty_decoder.hpp"

using namespace covtrack;
using namespace covtrack::serial6dof;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input input({data, size});
  const std::uint8_t options = input.byte();
  LibertyFormat format;
  format.units = options & 0x01 ? Units::Inches : Units::Centimetres;
  if (options & 0x02) format.extras.push_back(LibertyExtra::Timestamp);
  if (options & 0x04) format.extras.push_back(LibertyExtra::FrameCount);
  if (options & 0x08) format.extras.push_back(LibertyExtra::Stylus);
  LibertyDecoder decoder(format);
  fuzz::decode_and_check(decoder, input);
  return 0;
}
