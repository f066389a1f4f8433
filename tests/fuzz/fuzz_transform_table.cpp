// Transform tables (the CSV files a scene names in `transform_tables`, bulk static edges):
// parsed as `covtrack regions` and `view` parse them. A row that is accepted is an edge
// between two named, different frames with a finite rigid pose and a finite diagonal
// covariance; a table that is refused says where.
#include "covtrack/scene/transform_table.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fuzz::Input input({data, size});
  const auto table = scene::parse_transform_table(input.rest_text(), "fuzz.csv");
  if (!table) {
    FUZZ_CHECK(table.error().message.starts_with("fuzz.csv:"));
    return 0;
  }
  for (const scene::SceneTransform& t : *table) {
    FUZZ_CHECK(!t.parent.empty() && !t.child.empty() && t.parent != t.child);
    FUZZ_CHECK(t.T_parent_child.matrix().allFinite());
    const Mat3 R = t.T_parent_child.linear();
    FUZZ_CHECK((R.transpose() * R - Mat3::Identity()).norm() < 1e-9);
    FUZZ_CHECK(t.covariance.allFinite() && t.covariance.isDiagonal() && (t.covariance.diagonal().array() >= 0).all());
  }
  return 0;
}
