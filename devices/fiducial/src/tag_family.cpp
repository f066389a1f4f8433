#include "tag_family.hpp"

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>
#include <fmt/format.h>

namespace covtrack::fiducial {
namespace {

struct FamilyEntry {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

const std::vector<FamilyEntry>& family_table() {
  static const std::vector<FamilyEntry> table = {
      {"tag36h11", tag36h11_create, tag36h11_destroy},
      {"tag36h10", tag36h10_create, tag36h10_destroy},
      {"tag25h9", tag25h9_create, tag25h9_destroy},
      {"tag16h5", tag16h5_create, tag16h5_destroy},
      {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
      {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
      {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
      {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
      {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
  };
  return table;
}

}  // namespace

const std::vector<std::string>& tag_family_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& e : family_table()) n.emplace_back(e.name);
    return n;
  }();
  return names;
}

Result<std::shared_ptr<TagFamily>> TagFamily::open(const std::string& name) {
  for (const auto& e : family_table())
    if (name == e.name)
      return std::shared_ptr<TagFamily>(new TagFamily(name, e.create(), e.destroy));
  return fail(fmt::format("unknown AprilTag family '{}' (known: {})", name,
                          fmt::join(tag_family_names(), ", ")));
}

TagFamily::TagFamily(std::string name, apriltag_family* family,
                     void (*destroy)(apriltag_family*))
    : name_(std::move(name)), family_(family), destroy_(destroy) {}

TagFamily::~TagFamily() { destroy_(family_); }

int TagFamily::code_count() const { return static_cast<int>(family_->ncodes); }
int TagFamily::cells_across_border() const { return family_->width_at_border; }
int TagFamily::cells_across_total() const { return family_->total_width; }
bool TagFamily::reversed_border() const { return family_->reversed_border; }
std::array<std::array<double, 2>, 4> TagFamily::border_inner_white(int id) const {
  std::array<std::array<double, 2>, 4> white{};
  auto m = cells(id);
  const int n = family_->width_at_border;  // cells along an edge, corner cells included
  if (!m || family_->reversed_border || n < 4) return white;
  // Row 0 is the top as printed; the tag frame's y points down, so AprilTag's corner 0
  // (-s/2, +s/2) is bottom left and its edges run bottom (left to right), right (bottom
  // to top), top (right to left), left (top to bottom).
  const int first = (family_->total_width - n) / 2 + 1, last = first + n - 3;
  for (int e = 0; e < 4; ++e) {
    // Least-squares line w(t) = mean + slope (t - 1/2) over t in [0, 1] along the edge.
    double mean = 0, moment = 0;
    for (int j = 1; j + 1 < n; ++j) {
      const int i = j - 1;  // the j-th cell from the edge's start, counted inside the border
      const int row = e == 0 ? last : e == 1 ? last - i : e == 2 ? first : first + i;
      const int col = e == 0 ? first + i : e == 1 ? last : e == 2 ? last - i : first;
      if (m->at<std::uint8_t>(row, col) <= 127) continue;
      const double t0 = static_cast<double>(j) / n, t1 = static_cast<double>(j + 1) / n;
      mean += t1 - t0;
      moment += (t1 * t1 - t0 * t0) / 2 - (t1 - t0) / 2;
    }
    const double slope = 12 * moment;
    white[static_cast<std::size_t>(e)] = {mean - slope / 2, mean + slope / 2};
  }
  return white;
}

Result<cv::Mat> TagFamily::cells(int id) const {
  if (id < 0 || id >= code_count())
    return fail(fmt::format("tag id {} is outside {} (ids 0-{})", id, name_, code_count() - 1));
  const int total = family_->total_width;
  const int border = family_->width_at_border;
  cv::Mat m(total, total, CV_8U, cv::Scalar(0));
  // The layout: a one-cell white ring that marks the detected square (inside it for
  // "reversed border" families, outside it otherwise), then the data bits, whose
  // coordinates are relative to the detected square and may lie outside it.
  const int ring_width = border + (family_->reversed_border ? 0 : 2);
  const int ring_start = (total - ring_width) / 2;
  for (int i = 0; i < ring_width; ++i) {
    const int a = ring_start, b = ring_start + ring_width - 1, c = ring_start + i;
    m.at<std::uint8_t>(a, c) = m.at<std::uint8_t>(b, c) = 255;
    m.at<std::uint8_t>(c, a) = m.at<std::uint8_t>(c, b) = 255;
  }
  const int bits_start = (total - border) / 2;
  const std::uint64_t code = family_->codes[id];
  for (std::uint32_t i = 0; i < family_->nbits; ++i) {
    if (!((code >> (family_->nbits - 1 - i)) & 1u)) continue;
    const int x = static_cast<int>(family_->bit_x[i]) + bits_start;
    const int y = static_cast<int>(family_->bit_y[i]) + bits_start;
    if (x >= 0 && y >= 0 && x < total && y < total) m.at<std::uint8_t>(y, x) = 255;
  }
  return m;
}

}  // namespace covtrack::fiducial
