#include "calibration_entries.hpp"

#include <fmt/format.h>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

namespace covtrack {
namespace {

// A value's text where it is a scalar, "" where it is anything else (which no number is).
std::string scalar_text(const YAML::Node& node) { return node.IsScalar() ? node.Scalar() : std::string(); }

CalibrationValue value_of(const YAML::Node& node) {
  CalibrationValue v;
  if (node.IsScalar()) {
    v.kind = CalibrationValue::Kind::text;
    v.text = node.Scalar();
  } else if (node.IsMap() && node["data"].IsSequence()) {
    v.kind = CalibrationValue::Kind::matrix;
    for (const char* field : {"rows", "cols", "dt"}) {
      const YAML::Node part = node[field];
      if (!part.IsDefined()) continue;
      (field[0] == 'r' ? v.rows : field[0] == 'c' ? v.cols : v.dt) = scalar_text(part);
    }
    for (const YAML::Node& entry : node["data"]) v.data.push_back(scalar_text(entry));
  }
  return v;
}

std::string where(const YAML::Mark& mark) { return fmt::format("line {}, column {}", mark.line + 1, mark.column + 1); }

}  // namespace

Result<CalibrationEntries> read_yaml_entries(const std::string& text) {
  try {
    // OpenCV writes "%YAML:1.0" as its first line, which is not YAML's directive syntax
    // ("%YAML 1.0"); yaml-cpp passes it over as an unknown directive.
    const YAML::Node root = YAML::Load(text);
    if (!root.IsMap()) return fail("its top level is not a map of keys");
    CalibrationEntries entries;
    for (const auto& item : root) {
      if (!item.first.IsScalar()) return fail(fmt::format("a key at {} is not a name", where(item.first.Mark())));
      if (!entries.emplace(item.first.Scalar(), value_of(item.second)).second)
        return fail(fmt::format("key '{}' is given twice ({})", item.first.Scalar(), where(item.first.Mark())));
    }
    return entries;
  } catch (const YAML::DeepRecursion& e) {
    // Block nesting ("- - - 1"), which the text check does not count; yaml-cpp's own
    // message for it is "bad file".
    return fail(fmt::format("nested more than yaml-cpp reads ({} levels) at {}", e.depth(), where(e.mark)));
  } catch (const YAML::Exception& e) {
    // e.what() reads "yaml-cpp: error at line L, column C: what".
    return fail(fmt::format("not YAML: {}", e.what()));
  }
}

}  // namespace covtrack
