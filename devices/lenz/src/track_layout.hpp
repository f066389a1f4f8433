#pragma once
// A model-railway loop: straight and arc segments in 3-D, grouped into sections, each
// watched by one occupancy input; and the train that runs on it. The along-track
// coordinate s (metres, from the loop's origin, in the direction of travel) is what the
// dead reckoning estimates; this model turns it into poses.
#include <string>
#include <vector>

#include "covtrack/protocol/se3.hpp"

namespace covtrack::lenz {

enum class SegmentKind { Straight, Arc };

struct Segment {
  SegmentKind kind = SegmentKind::Straight;
  double length_m = 0;   // straight: along the track (3-D)
  double radius_m = 0;   // arc: horizontal radius
  double angle_rad = 0;  // arc: turn, positive to the left (counter-clockwise from above)
  double rise_m = 0;     // height gained over the segment
};

struct OccupancyInput {
  int module = 0;  // RS-bus address 1-128
  int input = 0;   // 1-8
};

struct Section {
  std::string name;
  OccupancyInput input;
  std::vector<Segment> segments;
  double start_s = 0;  // filled by TrackLayout::build
  double length_m = 0;
  double end_s() const { return start_s + length_m; }
};

struct Vehicle {
  std::string name;     // the sensor name
  double length_m = 0;
  double gap_m = 0;     // coupling gap to the vehicle in front (0 for the locomotive)
};

struct Train {
  double max_speed_mps = 0;
  double max_accel_mps2 = 0;   // also the largest deceleration
  bool reversible = false;     // may run backwards (against the loop order)
  std::vector<Vehicle> vehicles;  // the locomotive first
  // Distance from the locomotive's centre back to vehicle k's centre, along the track.
  double offset_behind_m(std::size_t k) const;
};

class TrackLayout {
 public:
  // Lays the sections' segments end to end from the origin; fails (with a message) when
  // the loop does not close within 1 cm and 1 degree.
  static std::string build(TrackLayout& layout, Vec3 origin_m, double heading_rad,
                           std::vector<Section> sections, Train train);

  double length_m() const { return length_m_; }
  const std::vector<Section>& sections() const { return sections_; }
  const Train& train() const { return train_; }
  std::size_t next(std::size_t section) const { return (section + 1) % sections_.size(); }
  std::size_t previous(std::size_t section) const { return (section + sections_.size() - 1) % sections_.size(); }
  std::size_t section_at(double s) const;
  double wrap(double s) const;

  // Pose on the track at s: x along the track (direction of travel), z as close to
  // world up as the slope allows.
  Pose pose_at(double s) const;
  // d/ds of the pose in the body frame: [1 0 0 | angular rate per metre].
  Vec6 body_rate(double s) const;

 private:
  struct Placed {
    Segment segment;
    double start_s = 0, length_m = 0;
    Vec3 start_m = Vec3::Zero();
    double heading_rad = 0;
  };
  Vec3 position_in(const Placed& p, double u, double* heading_out, Vec3* tangent_out) const;

  std::vector<Placed> placed_;
  std::vector<Section> sections_;
  Train train_;
  double length_m_ = 0;
};

}  // namespace covtrack::lenz
