// A Lenz track layout file (sections, occupancy inputs, segments, the train), read
// through a real file as the driver reads it; a layout that loads gives finite poses
// all along its loop.
#include "fuzz/fuzz_support.hpp"
#include "layout_config.hpp"

using namespace covtrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::ScratchFile file(".toml");
  const auto layout = lenz::load_layout(file.write({data, size}));
  if (!layout) {
    FUZZ_CHECK(!layout.error().message.empty());
    return 0;
  }
  const double length_m = layout->length_m();
  FUZZ_CHECK(fuzz::finite(length_m) && length_m > 0);
  for (const double s : {-length_m, 0.0, length_m / 3, length_m / 2, 2.5 * length_m}) {
    FUZZ_CHECK(layout->section_at(s) < layout->sections().size());
    FUZZ_CHECK(layout->pose_at(s).matrix().allFinite());
    FUZZ_CHECK(layout->body_rate(s).allFinite());
  }
  return 0;
}
