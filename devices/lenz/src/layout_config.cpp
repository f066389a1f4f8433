#include "layout_config.hpp"

#include <charconv>
#include <numbers>
#include <set>

#include <fmt/format.h>

#include "covtrack/protocol/channels.hpp"

namespace covtrack::lenz {

const TableSpec& layout_file_spec() {
  static const TableSpec spec{
      "track layout file (the lenz driver's layout key)",
      "lenz driver, covtrack emulate-lenz",
      {
          {"origin_m", ValueType::FloatArray, "m", "[0, 0, 0]", "where the first section starts", -1e4, 1e4, 3},
          {"heading_deg", ValueType::Float, "deg", "0", "direction of travel at the origin, "
           "counter-clockwise from the x axis", -360, 360},
          {"train", ValueType::Table, "", "", "the train: see train"},
          {"sections", ValueType::TableArray, "", "", "the sections in loop order, in the direction "
           "of travel (at least 3): see sections"},
      }};
  return spec;
}

const TableSpec& layout_train_spec() {
  static const TableSpec spec{
      "train (track layout file)",
      "lenz driver, covtrack emulate-lenz",
      {
          {"max_speed_mps", ValueType::Float, "m/s", "", "the train never goes faster", 0.001, 100},
          {"max_accel_mps2", ValueType::Float, "m/s^2", "", "largest acceleration and deceleration "
           "(bounds how fast the speed can change between section boundaries)", 0.001, 100},
          {"reversible", ValueType::Boolean, "", "false", "the train may also run backwards (against the "
           "loop order); the dead reckoning then allows it to come back towards the boundary it crossed"},
          {"vehicles", ValueType::TableArray, "", "", "locomotive first, then the cars: see train.vehicles"},
      }};
  return spec;
}

const TableSpec& layout_vehicle_spec() {
  static const TableSpec spec{
      "train.vehicles (track layout file)",
      "lenz driver, covtrack emulate-lenz",
      {
          {"name", ValueType::String, "", "", "sensor name of this vehicle (its pose stream)"},
          {"length_m", ValueType::Float, "m", "", "length over couplers", 0.001, 10},
          {"gap_m", ValueType::Float, "m", "0", "coupling gap to the vehicle in front", 0, 1},
      }};
  return spec;
}

const TableSpec& layout_section_spec() {
  static const TableSpec spec{
      "sections (track layout file)",
      "lenz driver, covtrack emulate-lenz",
      {
          {"name", ValueType::String, "", "", "name for messages"},
          {"input", ValueType::String, "", "", "occupancy input as \"module:input\": RS-bus "
           "address 1-128, input 1-8 (JMRI's XS99:3 is \"99:3\")"},
          {"segments", ValueType::TableArray, "", "", "the track pieces of this section, in order: see "
           "sections.segments"},
      }};
  return spec;
}

const TableSpec& layout_segment_spec() {
  static const TableSpec spec{
      "sections.segments (track layout file)",
      "lenz driver, covtrack emulate-lenz",
      {
          {"kind", ValueType::String, "", "", "\"straight\" or \"arc\""},
          {"length_m", ValueType::Float, "m", "required for a straight", "straight: length along the track", 0.001, 1e3},
          {"radius_m", ValueType::Float, "m", "required for an arc", "arc: radius", 0.01, 1e3},
          {"angle_deg", ValueType::Float, "deg", "required for an arc", "arc: turn, positive to the left", -360, 360},
          {"rise_m", ValueType::Float, "m", "0", "height gained over the segment", -100, 100},
      }};
  return spec;
}

std::vector<const TableSpec*> layout_specs() {
  return {&layout_file_spec(), &layout_train_spec(), &layout_vehicle_spec(), &layout_section_spec(),
          &layout_segment_spec()};
}

namespace {

constexpr double kDeg = std::numbers::pi / 180;

OccupancyInput parse_input(TableReader& r) {
  const std::string text = r.string("input");
  OccupancyInput in;
  const auto colon = text.find(':');
  bool ok = colon != std::string::npos;
  if (ok) {
    auto a = std::from_chars(text.data(), text.data() + colon, in.module);
    auto b = std::from_chars(text.data() + colon + 1, text.data() + text.size(), in.input);
    ok = a.ec == std::errc{} && a.ptr == text.data() + colon && b.ec == std::errc{} &&
         b.ptr == text.data() + text.size();
  }
  if (!ok || in.module < 1 || in.module > 128 || in.input < 1 || in.input > 8) {
    if (!text.empty())
      r.error("input", fmt::format("'{}' is not \"module:input\" with module 1-128 and input 1-8", text));
    return {};
  }
  return in;
}

Segment read_segment(TableReader& r) {
  Segment g;
  const std::string kind = r.choice("kind", {"straight", "arc"}, "straight");
  g.rise_m = r.number("rise_m", 0);
  if (kind == "straight") {
    g.kind = SegmentKind::Straight;
    if (!r.has("length_m")) r.error("length_m", "required for a straight");
    g.length_m = r.number("length_m", 0.1);
    if (r.has("radius_m") || r.has("angle_deg")) r.error("kind", "a straight takes length_m, not radius_m/angle_deg");
    if (std::abs(g.rise_m) >= g.length_m) r.error("rise_m", "must be smaller than length_m");
  } else {
    g.kind = SegmentKind::Arc;
    for (const char* key : {"radius_m", "angle_deg"})
      if (!r.has(key)) r.error(key, "required for an arc");
    g.radius_m = r.number("radius_m", 1);
    g.angle_rad = r.number("angle_deg", 10) * kDeg;
    if (r.has("length_m")) r.error("length_m", "an arc takes radius_m and angle_deg; its length follows");
    if (g.angle_rad == 0) r.error("angle_deg", "must not be 0");
  }
  return g;
}

}  // namespace

Result<TrackLayout> load_layout(const std::string& path) {
  auto text = read_config_text(path);
  if (!text) return std::unexpected(text.error());
  auto root = parse_toml(*text, path);
  if (!root) return std::unexpected(root.error());
  ConfigErrors errors;
  TableReader top(*root, "", layout_file_spec(), path, errors);
  const Vec3 origin = top.vec3("origin_m", Vec3::Zero());
  const double heading = top.number("heading_deg", 0) * kDeg;

  Train train;
  if (const toml::table* t = top.table("train")) {
    TableReader tr(*t, "train", layout_train_spec(), path, errors);
    train.max_speed_mps = tr.number("max_speed_mps", 1);
    train.max_accel_mps2 = tr.number("max_accel_mps2", 1);
    train.reversible = tr.boolean("reversible", false);
    std::set<std::string> names;
    const auto vehicles = tr.tables("vehicles");
    for (std::size_t i = 0; i < vehicles.size(); ++i) {
      TableReader vr(*vehicles[i], fmt::format("train.vehicles[{}]", i), layout_vehicle_spec(), path, errors);
      Vehicle v{vr.string("name"), vr.number("length_m", 0.1), vr.number("gap_m", 0)};
      if (!is_valid_name(v.name))
        vr.error("name", fmt::format("'{}' is not a valid sensor name (1-{} of A-Z a-z 0-9 _ -)", v.name, kMaxNameLength));
      if (!names.insert(v.name).second) vr.error("name", fmt::format("'{}' is used twice", v.name));
      train.vehicles.push_back(v);
    }
    if (vehicles.empty()) tr.error("vehicles", "needs at least the locomotive");
  }

  std::vector<Section> sections;
  std::set<std::pair<int, int>> inputs;
  const auto section_tables = top.tables("sections");
  if (section_tables.size() < 3 && top.has("sections"))
    top.error("sections", fmt::format("a loop needs at least 3 sections, found {}", section_tables.size()));
  for (std::size_t i = 0; i < section_tables.size(); ++i) {
    const std::string key = fmt::format("sections[{}]", i);
    TableReader sr(*section_tables[i], key, layout_section_spec(), path, errors);
    Section s;
    s.name = sr.string("name");
    s.input = parse_input(sr);
    if (s.input.module && !inputs.insert({s.input.module, s.input.input}).second)
      sr.error("input", fmt::format("{}:{} watches another section too", s.input.module, s.input.input));
    const auto segs = sr.tables("segments");
    if (segs.empty()) sr.error("segments", "needs at least one segment");
    for (std::size_t j = 0; j < segs.size(); ++j) {
      TableReader gr(*segs[j], fmt::format("{}.segments[{}]", key, j), layout_segment_spec(), path, errors);
      s.segments.push_back(read_segment(gr));
    }
    sections.push_back(std::move(s));
  }
  if (!errors.empty()) return fail(errors.joined());

  TrackLayout layout;
  if (auto problem = TrackLayout::build(layout, origin, heading, std::move(sections), std::move(train));
      !problem.empty())
    return fail(fmt::format("{}: sections: {}", path, problem));
  return layout;
}

}  // namespace covtrack::lenz
