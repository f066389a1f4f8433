#pragma once
// An AprilTag family opened by name (tag36h11, tagStandard41h12, ...), closed when the
// last user lets go. The renderer draws tags from the family's own code bits, the
// detector looks for them.
#include <array>
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
  // True where the detected square is light on a dark ring (tagStandard*, tagCircle*,
  // tagCustom48h12), false for a dark square on light paper (tag36h11 and the like).
  bool reversed_border() const;
  // Per edge of the detected square (edge k from corner k to k + 1, AprilTag's corner
  // order), where the data cells lining the inside of the one-cell black border are
  // white: there the border is only one cell thick and the detector's edge refinement is
  // pulled outward (corner_noise.hpp). As the detector fits a straight line along the
  // edge, so is "white" (1 for a white cell, 0 elsewhere, the border's corner cells
  // included) fitted by a straight line along it; returned at the edge's start and end.
  // All zero for reversed-border families, whose detected edge has no such border inside.
  std::array<std::array<double, 2>, 4> border_inner_white(int id) const;
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
