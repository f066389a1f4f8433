// A transform graph with a tracked camera: a head-worn camera on covtrack's optical/head
// stream (the demo's config/sim.toml) looks at a vase surveyed in the room. Ten times a
// second it prints the vase's screen-space error regions: the outer region holds every
// vertex of the vase with 95% confidence, the inner one is covered by the vase with it.
//   camera_regions [SECONDS]    (with covtrackd --config config/sim.toml running)
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <covtrack/client/regions.hpp>
#include <covtrack/client/subscriber.hpp>
#include <covtrack/client/transform_graph.hpp>
#include <covtrack/protocol/camera.hpp>
#include <covtrack/protocol/clock.hpp>

using namespace covtrack;

Mat6 covariance_of(double sigma_m, double sigma_rad) {  // BODY: translation, rotation
  Vec6 sigmas;
  sigmas << Vec3::Constant(sigma_m), Vec3::Constant(sigma_rad);
  return sigmas.cwiseAbs2().asDiagonal();
}

int main(int argc, char** argv) {
  const int seconds = argc > 1 ? std::stoi(argv[1]) : 10;
  // world -> head (tracked) -> camera (mounted, known to 1 mm); world -> vase (surveyed).
  client::TransformGraph graph;
  const StreamId head{"optical", "head"};
  (void)graph.add_tracked_edge("world", "head", head, {.max_linear_speed_m_s = 0.5, .max_angular_speed_rad_s = 1.2});
  Pose head_camera = Pose::Identity();  // looking along the head's y axis, 20 degrees down
  head_camera.translate(Vec3(0, 0.03, 0.05)).rotate(Eigen::AngleAxisd(-110 * std::numbers::pi / 180, Vec3::UnitX()));
  (void)graph.add_static_edge("head", "camera", head_camera, covariance_of(0.001, 0.005));
  Pose world_vase = Pose::Identity();
  world_vase.translate(Vec3(0, 0, 1.5));
  (void)graph.add_static_edge("world", "vase", world_vase, covariance_of(0.003, 0.003));

  Camera camera{.fx = 525, .fy = 525, .cx = 319.5, .cy = 239.5, .width_px = 640, .height_px = 480};
  std::vector<Vec3> vase;  // the corners of its 8 x 8 x 12 cm box
  for (double x : {-0.04, 0.04})
    for (double y : {-0.04, 0.04})
      for (double z : {-0.06, 0.06}) vase.emplace_back(x, y, z);

  auto subscriber = client::Subscriber::open({.pattern = head.key()});
  if (!subscriber) {
    std::fprintf(stderr, "camera_regions: %s\n", subscriber.error().message.c_str());
    return 1;
  }
  (void)(*subscriber)->on_pose(".*", [&](const client::TrackedTransform& t) { (void)graph.update(t.stream, t); });

  client::ObjectRegions regions;
  for (int frame = 0; frame < 10 * seconds; ++frame) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto T_camera_vase = graph.query("camera", "vase", now_us());
    if (!T_camera_vase) return std::fprintf(stderr, "camera_regions: %s\n", T_camera_vase.error().message.c_str()), 1;
    client::compute_object_regions(camera, *T_camera_vase, vase, {}, regions);
    if (!regions.valid) {  // no report yet, the head LOST, or the vase behind the camera
      std::printf("frame %d: no region\n", frame);
      continue;
    }
    Eigen::AlignedBox2d box;
    for (const auto& corner : regions.outer) box.extend(corner);
    std::printf("frame %d: outer %zu corners, %.0f px^2, [%.1f %.1f]-[%.1f %.1f] px; inner %.0f px^2\n", frame,
                regions.outer.size(), client::polygon_area(regions.outer), box.min().x(), box.min().y(),
                box.max().x(), box.max().y(), client::polygon_area(regions.inner));
  }
  (*subscriber)->stop();
}
