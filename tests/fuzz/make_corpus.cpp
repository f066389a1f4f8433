// Writes the generated part of the seed corpus (tests/fuzz/corpus/): valid inputs made by
// the project's own encoders, the bytes the emulators send. The config, layout and scene
// seeds are the shipped files, copied by make_corpus.sh. Run by hand after a format
// changes: make_corpus OUT_DIR (tests/fuzz/make_corpus.sh does both).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <covtrack/device_claim_t.hpp>
#include <covtrack/device_status_t.hpp>

#include "client/example_camera.hpp"
#include "covtrack/lcmlog/log_writer.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "covtrack/scene/transform_table.hpp"
#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/tracker_report.hpp"
#include "hydra_report.hpp"
#include "record_encoder.hpp"
#include "xpressnet_messages.hpp"

using namespace covtrack;
using Bytes = std::vector<std::uint8_t>;

namespace {

std::filesystem::path out_dir;

void write(const std::string& harness, const std::string& name, const Bytes& bytes) {
  const auto dir = out_dir / harness;
  std::filesystem::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                     static_cast<std::streamsize>(bytes.size()));
}

void append(Bytes& to, const Bytes& more) { to.insert(to.end(), more.begin(), more.end()); }

serial6dof::TrackerRecord record(int station, double x_m) {
  serial6dof::TrackerRecord r;
  r.station = station;
  r.position_m = Vec3(x_m, -0.12, 0.3);
  r.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vec3(0.2, 0.3, 0.9).normalized()));
  r.status_code = ' ';
  r.device_time_s = 12.5;
  r.buttons = 1;
  return r;
}

void xpressnet_seeds() {
  using namespace lenz;
  // The first byte of each seed chooses the read chunks (fuzz_xpressnet.cpp).
  Bytes replies{0};
  append(replies, encode_frame(reply_bytes(InterfaceVersion{0x30, 0x01}), Prefix::Reply));
  append(replies, encode_frame(reply_bytes(CommandStationVersion{0x36, 0x00})));
  append(replies, encode_frame(reply_bytes(CommandStationStatus{0x00})));
  append(replies, encode_frame(reply_bytes(Feedback{{{0, 0x45}, {1, 0x52}}}), Prefix::Unsolicited));
  append(replies, encode_frame(reply_bytes(Broadcast{BroadcastKind::TrackPowerOn})));
  write("xpressnet", "replies", replies);
  Bytes requests{7};
  append(requests, encode_frame(request_bytes(FeedbackRequest{3, true})));
  append(requests, encode_frame(request_bytes(CommandStationStatusRequest{})));
  append(requests, encode_frame(request_bytes(TrackPowerRequest{true})));
  write("xpressnet", "requests", requests);
  // A corrupted frame, then garbage with a stray header, then a good frame.
  Bytes noisy{3};
  Bytes bad = encode_frame(reply_bytes(Feedback{{{2, 0x41}}}));
  bad.back() ^= 0x5A;
  append(noisy, bad);
  append(noisy, {0x1F, 0x00, 0x33});
  append(noisy, encode_frame(reply_bytes(InterfaceNotice{0x04})));
  write("xpressnet", "noisy", noisy);
}

void serial6dof_seeds() {
  using namespace serial6dof;
  FastrakFormat fastrak{Units::Centimetres, {}, true};
  Bytes plain{0x00, 1};  // options, chunking
  append(plain, encode_fastrak_record(record(1, 0.2), fastrak));
  append(plain, encode_fastrak_record(record(2, -0.4), fastrak));
  append(plain, encode_fastrak_status(1, Units::Centimetres));
  write("fastrak", "two_stations_and_status", plain);
  fastrak = FastrakFormat{Units::Inches, {FastrakExtra::Timestamp, FastrakExtra::Buttons}, false};
  Bytes extras{0x01 | 0x02 | 0x04 | 0x08, 5};
  append(extras, encode_fastrak_record(record(3, 0.1), fastrak));
  write("fastrak", "inches_timestamp_buttons", extras);

  LibertyFormat liberty{Units::Centimetres, {}};
  Bytes frames{0x00, 2};
  append(frames, encode_liberty_record(record(1, 0.2), liberty));
  append(frames, encode_liberty_frame(1, 'U', 0, {'0'}));
  write("liberty", "pose_and_reply", frames);
  liberty = LibertyFormat{Units::Inches, {LibertyExtra::Timestamp, LibertyExtra::FrameCount}};
  Bytes patriot{0x01 | 0x02 | 0x04, 9};
  append(patriot, encode_liberty_record(record(2, -0.3), liberty, "PA"));
  write("liberty", "patriot_extras", patriot);

  Bytes standalone{0x00, 4};
  append(standalone, encode_flock_record(record(1, 0.2), FlockFormat{}));
  append(standalone, encode_flock_record(record(1, 0.21), FlockFormat{}));
  write("flock", "standalone", standalone);
  const FlockFormat group{72, true, 1};
  Bytes grouped{0x01 | 0x04, 6};
  append(grouped, encode_flock_record(record(2, 0.5), group));
  append(grouped, encode_flock_record(record(3, -0.5), group));
  write("flock", "group_mode_72in", grouped);
}

void hydra_seeds() {
  using namespace covtrack::hydra;
  HydraReport report;
  report.controllers[0].position_m = Vec3(-0.2, 0.1, -0.3);
  report.controllers[1].position_m = Vec3(0.2, 0.1, -0.3);
  report.controllers[1].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3::UnitY()));
  report.controllers[1].buttons = 0x05;
  report.controllers[1].joystick_x = 0.5;
  report.controllers[1].trigger = 0.25;
  Bytes reports;
  for (int i = 0; i < 3; ++i) {
    report.controllers[0].position_m.x() -= 0.001;
    reports.push_back(4);  // ms since the last report
    const auto one = build_hydra_report(report);
    reports.insert(reports.end(), one.begin(), one.end());
  }
  write("hydra", "three_reports", reports);
}

template <typename Msg>
Bytes with_channel(const std::string& channel, const Msg& msg) {
  Bytes out(channel.begin(), channel.end());
  out.push_back(0);
  Bytes bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  append(out, bytes);
  return out;
}

pose_cov_t pose_message(std::int8_t status) {
  pose_cov_t m{};
  m.measurement_time_us = 1'700'000'000'000'000;
  m.publish_time_us = m.measurement_time_us + 150;
  m.sequence = 42;
  m.device = "rig";
  m.sensor = "tool";
  m.parent_frame = "world";
  m.child_frame = "tool";
  Mat6 cov = Mat6::Identity() * 1e-6;
  cov(0, 1) = cov(1, 0) = 2e-7;
  set_pose(m, pose_from(Vec3(0.1, 0.2, 0.3), Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Vec3::UnitZ()))), cov);
  m.status = status;
  return m;
}

void wire_message_seeds() {
  write("wire_message", "pose_ok", with_channel("covtrack/pose/rig/tool", pose_message(pose_cov_t::STATUS_OK)));
  write("wire_message", "pose_lost", with_channel("covtrack/pose/rig/tool", pose_message(pose_cov_t::STATUS_LOST)));
  device_status_t s{};
  s.time_us = 1'700'000'000'000'000;
  s.device = "rig";
  s.driver = "sim";
  s.state = device_status_t::STATE_RUNNING;
  s.rate_hz = 100;
  s.last_error = "";
  s.detail = "ok";
  s.instance_id = 77;
  s.host = "bench";
  s.pid = 1234;
  s.heartbeat_period_us = 1'000'000;
  write("wire_message", "status", with_channel("covtrack/status/rig", s));
  device_claim_t c{};
  c.time_us = s.time_us;
  c.device = "rig";
  c.instance_id = 77;
  c.host = "bench";
  c.pid = 1234;
  c.claimed_us = s.time_us;
  c.stage = device_claim_t::STAGE_HOLDING;
  write("wire_message", "claim", with_channel("covtrack/claim/rig", c));
}

void lcm_log_seeds() {
  const auto path = (out_dir / "lcm_log" / "poses_out_of_order").string();
  std::filesystem::create_directories(out_dir / "lcm_log");
  auto writer = lcmlog::LogWriter::create(path, true);
  if (!writer) throw std::runtime_error(writer.error().message);
  const auto encoded = [](const auto& msg) {
    std::string bytes(static_cast<std::size_t>(msg.getEncodedSize()), '\0');
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    return bytes;
  };
  // Out of timestamp order on purpose, as logs of `covtrack record` can be.
  const auto pose = encoded(pose_message(pose_cov_t::STATUS_OK));
  for (const std::int64_t t : {2'000, 1'000, 3'000}) {
    if (auto r = writer->write(t, "covtrack/pose/rig/tool", {reinterpret_cast<const std::byte*>(pose.data()), pose.size()}); !r)
      throw std::runtime_error(r.error().message);
  }
}

// fuzz_regions.cpp's layout: an options byte, the number of objects less one, then per
// object its vertex count less one and either a pose (translation, rotation vector, the
// covariance's upper triangle, an unbounded byte) and its vertices, or outer and inner
// polygons (the inner's count as it is); then the label's size. Numbers are raw
// little-endian doubles.
struct RegionsSeed {
  Bytes bytes;
  void byte(std::uint8_t b) { bytes.push_back(b); }
  void numbers(std::initializer_list<double> values) {
    for (double v : values) {
      std::uint8_t raw[8];
      std::memcpy(raw, &v, sizeof raw);
      bytes.insert(bytes.end(), raw, raw + 8);
    }
  }
  // A box of half-size s at (x, y, z), turned a little, with a covariance of 2 mm and
  // about 1 degree (or `sigma_scale` times that).
  void box_object(double x, double y, double z, double s, double sigma_scale = 1) {
    byte(8 - 1);
    numbers({x, y, z, 0.1, 0.2, 0.3});
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) numbers({i != j ? 0.0 : sigma_scale * sigma_scale * (i < 3 ? 4e-6 : 3e-4)});
    byte(0);
    for (int k = 0; k < 8; ++k) numbers({k & 1 ? s : -s, k & 2 ? 0.7 * s : -0.7 * s, k & 4 ? 0.5 * s : -0.5 * s});
    numbers({60, 14});
  }
  void square_polygons(double x, double y, double half) {
    byte(4 - 1);
    numbers({x - half, y - half, x + half, y - half, x + half, y + half, x - half, y + half});
    byte(4);
    numbers({x - half / 2, y - half / 2, x + half / 2, y - half / 2, x + half / 2, y + half / 2, x - half / 2,
             y + half / 2});
    numbers({50, 12});
  }
};

void regions_seeds() {
  RegionsSeed boxes;  // four boxes in view, unscented, whole-object scale
  boxes.byte(0), boxes.byte(3);
  boxes.box_object(0, 0, 2, 0.1), boxes.box_object(0.3, 0.1, 2.5, 0.15), boxes.box_object(-0.3, -0.2, 1.5, 0.05, 3),
      boxes.box_object(0.05, 0.05, 0.3, 0.02, 10);
  write("regions", "boxes", boxes.bytes);
  RegionsSeed linear;  // first order, per-vertex scale, no distortion, the other policy
  linear.byte(1 | 2 | 4 | 32), linear.byte(1);
  linear.box_object(0.1, 0, 1.2, 0.2), linear.box_object(-0.2, 0.1, 3, 0.3, 5);
  write("regions", "linear_boxes", linear.bytes);
  RegionsSeed polygons;  // the placer's polygons from the input, labels never inside
  polygons.byte(8 | 16), polygons.byte(2);
  polygons.square_polygons(100, 100, 40), polygons.square_polygons(130, 110, 30), polygons.square_polygons(600, 460, 50);
  write("regions", "polygons", polygons.bytes);
}

// What a VRPN client sends covtrackd's VRPN server: its cookie and descriptions, a ping of
// Tracker0, a tracker report and a UDP description, made by a session of the client's
// names once it has the server's cookie. The first byte chooses the harness's chunks.
void vrpn_seeds() {
  using namespace covtrack::vrpn;
  Session client({"Tracker0"}, {std::string(kPing), std::string(kTrackerPosQuat)});
  const Cookie server_cookie = make_cookie();
  (void)client.receive(server_cookie, 0);
  const std::int64_t t = 1'700'000'000'000'000;
  client.send("Tracker0", kPing, t, {});
  client.send("Tracker0", kTrackerPosQuat, t,
              encode_pos_quat(report_of(1, pose_from(Vec3(0.1, 0.2, 0.3), Eigen::Quaterniond(0.8, 0.6, 0, 0)))));
  client.describe_udp("127.0.0.1", 4500, t);
  Bytes stream{7};
  append(stream, client.take_output());
  write("vrpn", "client_handshake_ping_report", stream);
}

// OpenCV's XML and JSON, as cv::FileStorage writes them (the YAML seeds are the shipped
// files).
void camera_seeds() {
  Camera camera = test::example_camera();
  camera.intrinsic_sigmas_px = {1.8, 1.7, 0.9, 1.1};
  std::filesystem::create_directories(out_dir / "camera");
  for (const char* name : {"opencv_640x480.xml", "opencv_640x480.json"})
    if (!save_camera(camera, out_dir / "camera" / name)) std::exit(1);
}

// A scene's bulk edges: a comment, the header, a chain of three rows.
void transform_table_seeds() {
  const std::string table = "# a chain from the room to a tool\n" + std::string(scene::kTransformTableHeader) +
                            "\nroom,rig,0.5,0,2.1,0,-90,15,0.001,0.001,0.002,0.002,0.002,0.004\n"
                            "rig,arm,0,0.25,0,5,0,0,0.0005,0.0005,0.0005,0.001,0.001,0.001\n"
                            "arm,tool,0.1,0,0.05,0,45,-30,0,0,0,0,0,0\n";
  write("transform_table", "chain.csv", Bytes(table.begin(), table.end()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_corpus OUT_DIR\n");
    return 2;
  }
  out_dir = argv[1];
  xpressnet_seeds();
  serial6dof_seeds();
  hydra_seeds();
  wire_message_seeds();
  lcm_log_seeds();
  regions_seeds();
  vrpn_seeds();
  camera_seeds();
  transform_table_seeds();
  return 0;
}
