// An object's screen regions and the frame's labels from any numbers: poses, covariances
// (indefinite, NaN, 1e300), vertices and label sizes as a network message or an
// application could hand them over, through compute_object_regions and the label placer;
// or the placer's polygons straight from the input (not convex, repeated points, NaN).
// Neither may crash, hang or hand out what their headers rule out: regions of an invalid
// object are empty, those of a valid one finite (a NaN in, or an overflow on the way,
// makes it invalid and flags it `not_finite`); placed labels are on screen, of the asked
// size and clear of each other.
#include <cstring>
#include <vector>

#include "client/example_camera.hpp"
#include "covtrack/client/label_placer.hpp"
#include "covtrack/client/regions.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

constexpr int kMaxObjects = 6;
constexpr int kMaxVertices = 24;
const Box kScreen{Vec2(0, 0), Vec2(640, 480)};

// Doubles from the input, any bit pattern; zero once it runs out.
double number(fuzz::Input& in) {
  std::uint8_t bytes[8];
  for (std::uint8_t& b : bytes) b = in.byte();
  double v;
  std::memcpy(&v, bytes, sizeof v);
  return v;
}

Vec2 number2(fuzz::Input& in) {
  const double x = number(in);
  return {x, number(in)};
}

Vec3 number3(fuzz::Input& in) {
  const double x = number(in), y = number(in);
  return {x, y, number(in)};
}

UncertainPose pose(fuzz::Input& in) {
  UncertainPose p;
  const Vec3 t = number3(in), r = number3(in);
  const double angle = r.norm();
  p.T = pose_from(t, angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle)) : Eigen::Quaterniond::Identity());
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) p.covariance(i, j) = p.covariance(j, i) = number(in);
  p.unbounded = in.byte() & 1;
  return p;
}

bool all_finite(const Polygon& polygon) {
  for (const Vec2& v : polygon)
    if (!v.allFinite()) return false;
  return true;
}

void check_regions(const ObjectRegions& r, std::size_t vertices) {
  FUZZ_CHECK(r.vertices.size() == vertices);
  if (!r.valid) {
    FUZZ_CHECK(r.outer.empty() && r.inner.empty());
    return;
  }
  FUZZ_CHECK(!r.outer.empty() && all_finite(r.outer));
  FUZZ_CHECK(all_finite(r.inner));
  // Infinite where the error is too large to compute (the Level of Error's last level).
  FUZZ_CHECK(r.assessment >= 0);
  FUZZ_CHECK(std::isfinite(r.outer_scale) && r.outer_scale > 0);
}

void check_labels(std::span<const LabelRequest> requests, const std::vector<PlacedLabel>& labels) {
  FUZZ_CHECK(labels.size() == requests.size());
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const PlacedLabel& l = labels[i];
    if (!l.anchored) {
      FUZZ_CHECK(l.placement == LabelPlacement::corner_list);
      continue;
    }
    FUZZ_CHECK(l.placement != LabelPlacement::corner_list);
    FUZZ_CHECK(l.on_screen && box_inside(l.box, kScreen, 1e-6));
    // The asked size, where it is one (a negative or non-finite side counts as zero).
    const Vec2& asked = requests[i].size_px;
    for (int k = 0; k < 2; ++k) {
      const double side = std::isfinite(asked[k]) ? std::max(asked[k], 0.0) : 0.0;
      FUZZ_CHECK(std::abs((l.box.max - l.box.min)[k] - side) <= 1e-9 * (1 + side));
    }
    for (std::size_t j = 0; j < i; ++j)
      if (labels[j].anchored) FUZZ_CHECK(!boxes_overlap(l.box, labels[j].box));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in({data, size});
  const std::uint8_t options = in.byte();
  const int objects = 1 + in.byte() % kMaxObjects;
  const Camera camera = [&] {
    Camera c = test::example_camera();
    if (options & 1) c.k1 = c.k2 = c.p1 = c.p2 = c.k3 = 0;
    return c;
  }();
  ObjectRegionOptions region_options;
  if (options & 2) region_options.projection.method = ProjectionMethod::linear;
  region_options.regions.whole_object = !(options & 4);
  const bool polygons_from_input = options & 8;
  const LabelPlacerOptions label_options{.screen = kScreen,
                                         .allow_inside = !(options & 16),
                                         .policy = options & 32 ? most_free_space_policy() : fixed_order_policy(),
                                         .avoid_other_objects = !(options & 64)};

  std::vector<LabelRequest> requests(objects);
  for (LabelRequest& request : requests) {
    const int n = 1 + in.byte() % kMaxVertices;
    if (polygons_from_input) {
      for (int k = 0; k < n; ++k) request.outer.push_back(number2(in));
      for (int k = 0, m = in.byte() % kMaxVertices; k < m; ++k) request.inner.push_back(number2(in));
    } else {
      const UncertainPose T = pose(in);
      std::vector<Vec3> vertices;
      for (int k = 0; k < n; ++k) vertices.push_back(number3(in));
      const ObjectRegions r = compute_object_regions(camera, T, vertices, region_options);
      check_regions(r, vertices.size());
      request.outer = r.outer;
      request.inner = r.inner;
    }
    request.size_px = number2(in);
  }
  LabelPlacer placer;
  std::vector<PlacedLabel> labels;
  placer.place(requests, label_options, labels);
  check_labels(requests, labels);
  // The placer keeps its memory from call to call: the same requests, the same labels.
  std::vector<PlacedLabel> again;
  placer.place(requests, label_options, again);
  FUZZ_CHECK(again.size() == labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i)
    FUZZ_CHECK(again[i].placement == labels[i].placement && again[i].box.min == labels[i].box.min);
  return 0;
}
