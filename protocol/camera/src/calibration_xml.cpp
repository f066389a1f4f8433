#include "calibration_entries.hpp"

#include <sstream>

#include <fmt/format.h>
#include <tinyxml2.h>

namespace covtrack {
namespace {

// An element's text, outside white space and OpenCV's quotes removed.
std::string text_of(const tinyxml2::XMLElement* element) {
  std::string text = element->GetText() ? element->GetText() : "";
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  text = text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
  if (text.size() >= 2 && text.front() == '"' && text.back() == '"') text = text.substr(1, text.size() - 2);
  return text;
}

// Where an element has children, the text of the one named `name`: nullopt without one,
// "" where that one has children of its own (no number does).
std::optional<std::string> child_text(const tinyxml2::XMLElement* element, const char* name) {
  const tinyxml2::XMLElement* child = element->FirstChildElement(name);
  if (!child) return std::nullopt;
  return child->FirstChildElement() ? std::string() : text_of(child);
}

CalibrationValue value_of(const tinyxml2::XMLElement* element) {
  CalibrationValue v;
  if (!element->FirstChildElement()) {
    v.kind = CalibrationValue::Kind::text;
    v.text = text_of(element);
    return v;
  }
  // A matrix: <rows>, <cols>, <dt> and <data> holding its numbers apart by white space.
  const std::optional<std::string> data = child_text(element, "data");
  if (!data) return v;
  v.kind = CalibrationValue::Kind::matrix;
  v.rows = child_text(element, "rows");
  v.cols = child_text(element, "cols");
  v.dt = child_text(element, "dt");
  std::istringstream numbers(*data);
  for (std::string number; numbers >> number;) v.data.push_back(number);
  return v;
}

}  // namespace

Result<CalibrationEntries> read_xml_entries(const std::string& text) {
  tinyxml2::XMLDocument document;
  if (document.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    return fail(fmt::format("not XML: {} (line {})", document.ErrorName(), document.ErrorLineNum()));
  const tinyxml2::XMLElement* root = document.RootElement();
  if (!root || std::string_view(root->Name()) != "opencv_storage")
    return fail("not OpenCV's XML: its top element is not <opencv_storage>");
  CalibrationEntries entries;
  for (const tinyxml2::XMLElement* e = root->FirstChildElement(); e; e = e->NextSiblingElement())
    if (!entries.emplace(e->Name(), value_of(e)).second)
      return fail(fmt::format("key '{}' is given twice (line {})", e->Name(), e->GetLineNum()));
  return entries;
}

}  // namespace covtrack
