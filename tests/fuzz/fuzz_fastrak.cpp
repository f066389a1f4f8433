// Polhemus FASTRAK / IS-900 binary records and status records: the first byte picks the
// output format (units, extra items, terminator), the rest is the serial stream.
#include "fastrak_decoder.hpp"
#include "fuzz/serial6dof_checks.hpp"

using namespace covtrack;
using namespace covtrack::serial6dof;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input input({data, size});
  const std::uint8_t options = input.byte();
  FastrakFormat format;
  format.units = options & 0x01 ? Units::Inches : Units::Centimetres;
  format.crlf_terminator = !(options & 0x02);
  if (options & 0x04) format.extras.push_back(FastrakExtra::Timestamp);
  if (options & 0x08) format.extras.push_back(FastrakExtra::Buttons);
  if (options & 0x10) format.extras.push_back(FastrakExtra::Stylus);
  if (options & 0x20) format.extras.push_back(FastrakExtra::Joystick);
  FastrakDecoder decoder(format);
  fuzz::decode_and_check(decoder, input);
  return 0;
}
