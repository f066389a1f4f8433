// Ascension Flock of Birds POSITION/QUATERNION records: the first byte picks the full
// scale and group mode, the rest is the serial stream.
#include "flock_decoder.hpp"
#include "fuzz/serial6dof_checks.hpp"

using namespace covtrack;
using namespace covtrack::serial6dof;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input input({data, size});
  const std::uint8_t options = input.byte();
  FlockFormat format;
  format.position_scale_in = (options & 0x03) == 1 ? 72 : (options & 0x03) == 2 ? 144 : 36;
  format.group_mode = options & 0x04;
  FlockDecoder decoder(format);
  fuzz::decode_and_check(decoder, input);
  return 0;
}
