#include "covtrack/scene/transform_table.hpp"

#include <array>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/devices/pose_keys.hpp"

namespace covtrack::scene {
namespace {

constexpr std::size_t kColumns = 14;  // parent, child, 3 position, 3 angles, 6 sigmas
constexpr std::size_t kMaxReported = 10;

// The numeric columns keep the ranges of the scene keys they stand for, so a row and a
// [[transform]] table accept the same values.
struct NumberColumn {
  double min, max;
};

std::array<NumberColumn, kColumns - 2> number_columns() {
  const auto range_of = [](const std::vector<KeySpec>& keys, std::string_view key) {
    for (const KeySpec& k : keys)
      if (k.key == key) return NumberColumn{k.min, k.max};
    return NumberColumn{-INFINITY, INFINITY};
  };
  const auto pose = pose_keys(), cov = covariance_keys();
  const NumberColumn position = range_of(pose, "position_m"), angle = range_of(pose, "rotation_rpy_deg"),
                     sigma_m = range_of(cov, "sigma_m"), sigma_rad = range_of(cov, "sigma_rad");
  return {position, position, position, angle,   angle,     angle,
          sigma_m,  sigma_m,  sigma_m,  sigma_rad, sigma_rad, sigma_rad};
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// Splits at commas into exactly kColumns fields; false if the count differs.
bool split_row(std::string_view line, std::array<std::string_view, kColumns>& fields, std::size_t& count) {
  count = 0;
  for (;;) {
    const auto comma = line.find(',');
    if (count < kColumns) fields[count] = trim(line.substr(0, comma));
    ++count;
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  return count == kColumns;
}

bool is_frame_name(std::string_view s) {
  return !s.empty() && s.find_first_of(" \"'") == std::string_view::npos;
}

class RowErrors {
 public:
  explicit RowErrors(const std::string& source) : source_(source) {}
  void add(std::size_t line, const std::string& message) {
    if (count_++ < kMaxReported) text_ += fmt::format("{}{}:{}: {}", text_.empty() ? "" : "\n", source_, line, message);
  }
  bool empty() const { return count_ == 0; }
  std::string joined() const {
    return count_ <= kMaxReported ? text_ : fmt::format("{}\n... and {} more errors", text_, count_ - kMaxReported);
  }

 private:
  const std::string& source_;
  std::string text_;
  std::size_t count_ = 0;
};

// The header's column names, split as a row is.
std::array<std::string_view, kColumns> header_names() {
  std::array<std::string_view, kColumns> names;
  std::size_t count = 0;
  split_row(kTransformTableHeader, names, count);
  return names;
}

}  // namespace

Result<std::vector<SceneTransform>> parse_transform_table(std::string_view text, const std::string& source) {
  static const auto ranges = number_columns();
  static const auto names = header_names();
  RowErrors errors(source);
  std::vector<SceneTransform> out;
  out.reserve(text.size() / 64);
  bool header_seen = false;
  std::array<std::string_view, kColumns> fields;
  std::array<double, kColumns - 2> v{};
  std::size_t line_number = 0;
  while (!text.empty()) {
    const auto end = text.find('\n');
    const std::string_view line = trim(text.substr(0, end));
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    ++line_number;
    if (line.empty() || line.front() == '#') continue;
    if (!header_seen) {
      header_seen = true;
      if (line != kTransformTableHeader)
        errors.add(line_number, fmt::format("the header must be exactly '{}'", kTransformTableHeader));
      continue;
    }
    std::size_t count = 0;
    if (!split_row(line, fields, count)) {
      errors.add(line_number, fmt::format("{} columns, expected {}", count, kColumns));
      continue;
    }
    bool ok = true;
    for (std::size_t c = 0; c < 2; ++c)
      if (!is_frame_name(fields[c])) {
        errors.add(line_number, fmt::format("column {}: '{}' is not a frame name", names[c], fields[c]));
        ok = false;
      }
    for (std::size_t c = 2; c < kColumns; ++c) {
      const std::string_view f = fields[c];
      double& x = v[c - 2];
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), x);
      if (ec != std::errc() || ptr != f.data() + f.size() || !std::isfinite(x)) {
        errors.add(line_number, fmt::format("column {}: '{}' is not a finite number", names[c], f));
        ok = false;
      } else if (x < ranges[c - 2].min || x > ranges[c - 2].max) {
        errors.add(line_number, fmt::format("column {}: {} is outside [{}, {}]", names[c], x,
                                            ranges[c - 2].min, ranges[c - 2].max));
        ok = false;
      }
    }
    if (!ok) continue;
    if (fields[0] == fields[1]) {
      errors.add(line_number, fmt::format("'{}' cannot be its own parent", fields[0]));
      continue;
    }
    SceneTransform& t = out.emplace_back();
    t.parent = fields[0];
    t.child = fields[1];
    t.T_parent_child.translation() = Vec3(v[0], v[1], v[2]);
    t.T_parent_child.linear() = rotation_from_rpy_deg(Vec3(v[3], v[4], v[5]));
    for (int i = 0; i < 6; ++i) t.covariance(i, i) = v[6 + i] * v[6 + i];
  }
  if (!header_seen) errors.add(line_number, fmt::format("no header: expected '{}'", kTransformTableHeader));
  if (!errors.empty()) return fail(errors.joined());
  return out;
}

Result<std::vector<SceneTransform>> load_transform_table(const std::string& path) {
  // Bulk data: about 3 million links (a row is about 80 bytes), far past a config's bound.
  constexpr std::size_t kMaxTableBytes = std::size_t(256) << 20;
  auto text = read_config_text(path, kMaxTableBytes);
  if (!text) return std::unexpected(text.error());
  return parse_transform_table(*text, path);
}

}  // namespace covtrack::scene
