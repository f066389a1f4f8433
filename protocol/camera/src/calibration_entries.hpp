#pragma once
// A calibration file's top-level entries, in one shape for every syntax covtrack reads:
// OpenCV's FileStorage YAML, XML and JSON (which the YAML reader reads), and ROS's
// camera_info YAML. yaml-cpp and tinyxml2 read the text: both report damaged text as an
// error and bound their recursion, where OpenCV 4.6's own reader loops forever on some
// damaged YAML (docs/design.md).
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

// One top-level value: text (a number, a name), a matrix, or anything else (a list, a map
// without a data list), which no key covtrack reads may hold.
struct CalibrationValue {
  enum class Kind { text, matrix, other };
  Kind kind = Kind::other;
  std::string text;  // Kind::text: the scalar as written, quotes removed
  // Kind::matrix: OpenCV's {rows, cols, dt, data}, each as written (nullopt where the
  // file has none; "" where it is not a scalar). ROS's matrices have no dt.
  std::optional<std::string> rows, cols, dt;
  std::vector<std::string> data;
};

using CalibrationEntries = std::map<std::string, CalibrationValue, std::less<>>;

// The entries of a YAML document's top-level map; an error for text that is not YAML, a
// top level that is not a map, or a key given twice. Errors say what and where (line,
// column), not which file: the caller adds its name.
Result<CalibrationEntries> read_yaml_entries(const std::string& text);

// The same for OpenCV's XML: the children of <opencv_storage>.
Result<CalibrationEntries> read_xml_entries(const std::string& text);

}  // namespace covtrack
