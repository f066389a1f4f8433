#pragma once
// An AprilTag family opened by name (tag36h11, tagStandard41h12, ...), closed when the
// last user lets go. The renderer draws tags from the family's own code bits, the
// detector looks for them.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/protocol/result.hpp"

struct apriltag_family;

namespace covtrack::fiducial {

class TagFamily {
 public:
  static Result<std::shared_ptr<TagFamily>> open(const std::string& name);
  ~TagFamily();
  TagFamily(const TagFamily&) = delete;
  TagFamily& operator=(const TagFamily&) = delete;

  apriltag_family* get() const { return family_; }
  const std::string& name() const { return name_; }
  int code_count() const;
  // Cells across the detected square (the corners the detector reports bound it) and
  // across the whole printed tag (which may extend beyond that square).
  int cells_across_border() const;
  int cells_across_total() const;
  // Cells of one uniform shade just beyond the detected square's edge: the family's white
  // ring plus the paper around the print, or the one black ring of a reversed-border
  // family (its data bits follow). The detector's edge refinement needs a few pixels of it.
  double quiet_cells(double paper_margin_cells) const;
  // The printed tag `id` as total x total cells, 0 black and 255 white, row 0 at the top.
  Result<cv::Mat> cells(int id) const;

 private:
  TagFamily(std::string name, apriltag_family* family, void (*destroy)(apriltag_family*));
  std::string name_;
  apriltag_family* family_;
  void (*destroy_)(apriltag_family*);
};

// Every family name open() accepts.
const std::vector<std::string>& tag_family_names();

}  // namespace covtrack::fiducial
