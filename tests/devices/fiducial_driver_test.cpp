// The fiducial driver on rendered image sequences: poses near the truth with finite
// covariances, decodable raw detections, the frames themselves when asked (publish_images),
// and clear errors for a missing camera, an unreadable calibration and a corrupt video.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "covtrack/devices/fiducial/fiducial_driver.hpp"
#include "covtrack/emulators/fiducial/tag_renderer.hpp"
#include "fiducial_config.hpp"
#include "fiducial_scene.hpp"
#include "raw_detection.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
namespace fs = std::filesystem;

namespace {

class Sink : public SampleSink {
 public:
  void pose(const PoseSample& s) override { std::lock_guard l(m); poses.push_back(s); }
  void truth(const TruthSample&) override {}
  void raw(ByteDirection, const std::uint8_t* d, std::size_t n) override {
    std::lock_guard l(m);
    raws.emplace_back(d, d + n);
  }
  void image(const ImageSample& s) override { std::lock_guard l(m); images.push_back(s); }
  void count_error(const std::string&) override { ++errors; }
  void count_resync() override {}
  void count_drop() override {}
  void running(const std::string& detail) override { std::lock_guard l(m); details.push_back(detail); }
  std::size_t raw_count() { std::lock_guard l(m); return raws.size(); }
  std::mutex m;
  std::vector<PoseSample> poses;
  std::vector<std::vector<std::uint8_t>> raws;
  std::vector<ImageSample> images;
  std::vector<std::string> details;  // the running() detail of each frame
  int errors = 0;
};

struct Scene {
  fs::path dir;
  std::vector<RenderedTag> tags;
};

Scene render_sequence(const std::string& name, int frames) {
  Scene s;
  s.dir = fs::path(::testing::TempDir()) / fmt::format("fiducial_{}_{}", name, getpid());
  fs::create_directories(s.dir);
  const Camera cam = test::small_camera();
  EXPECT_TRUE(save_camera(cam, s.dir / "camera.yml").has_value());
  auto family = TagFamily::open("tag36h11");
  s.tags = {{2, 0.1, test::tag_pose(0.8, 25, 10, 30, -0.1, 0)},
            {9, 0.1, test::tag_pose(1.0, -20, -5, 60, 0.15, 0.05)}};
  const cv::Mat clean = render_tags(cam, **family, s.tags, RenderLook{});
  std::mt19937_64 rng(3);
  for (int f = 0; f < frames; ++f)
    cv::imwrite((s.dir / fmt::format("frame_{:04d}.png", f)).string(), add_sensor_noise(clean, 3, rng));
  return s;
}

// The frames and camera in `dir`, played once as fast as they are read.
FiducialConfig sequence_config(const fs::path& dir) {
  FiducialConfig c;
  c.device = "cam";
  c.source = (dir / "frame_%04d.png").string();
  c.calibration = (dir / "camera.yml").string();
  c.detector.decimate = 1;
  c.rate_hz = 0;
  c.loop = false;
  return c;
}

FiducialConfig config_for(const Scene& s) {
  FiducialConfig c = sequence_config(s.dir);
  c.tag_size_m = {{2, 0.1}, {9, 0.1}};
  return c;
}

// Four 0.06 m tags (ids 0-3) on a board, 0.11 m apart, as a bundle's config lists them.
TagBundle board_bundle() {
  TagBundle b{"board", {}, false};
  for (int id = 0; id < 4; ++id) {
    Pose T = Pose::Identity();
    T.translation() = Vec3((id % 2 - 0.5) * 0.11, (id / 2 - 0.5) * 0.11, 0);
    b.tags.push_back({id, 0.06, T});
  }
  return b;
}

struct BundleScene {
  fs::path dir;
  Pose T_camera_board;
};

// Frames of the board (its tag `moved`, if any, 2 cm off its place) and tag 9 beside it;
// the last `without_board` frames show tag 9 alone.
BundleScene render_bundle_sequence(const std::string& name, int frames, int without_board, int moved = -1) {
  BundleScene s{fs::path(::testing::TempDir()) / fmt::format("fiducial_bundle_{}_{}", name, getpid()),
                test::tag_pose(0.55, 20, 10, 15)};
  fs::create_directories(s.dir);
  const Camera cam = test::camera(640, 480, 60);
  EXPECT_TRUE(save_camera(cam, s.dir / "camera.yml").has_value());
  auto family = TagFamily::open("tag36h11");
  const RenderedTag tag9{9, 0.08, test::tag_pose(0.7, -15, 0, 0, 0.2, 0.1)};
  std::vector<RenderedTag> with_board{tag9};
  for (BundleTag t : board_bundle().tags) {
    if (t.id == moved) t.T_bundle_tag.translation().y() += 0.02;
    with_board.push_back({t.id, t.size_m, s.T_camera_board * t.T_bundle_tag});
  }
  std::mt19937_64 rng(7);
  for (int f = 0; f < frames; ++f) {
    const cv::Mat clean = render_tags(cam, **family, f < frames - without_board ? with_board : std::vector{tag9},
                                      RenderLook{});
    cv::imwrite((s.dir / fmt::format("frame_{:04d}.png", f)).string(), add_sensor_noise(clean, 3, rng));
  }
  return s;
}

FiducialConfig bundle_config_for(const BundleScene& s) {
  FiducialConfig c = sequence_config(s.dir);
  c.tag_size_m = {{9, 0.08}};
  c.bundles = {board_bundle()};
  return c;
}

// Runs the driver until it returns, or until `frames` raw records arrived (then stops it).
Result<void> run_driver(const FiducialConfig& c, Sink& sink, std::size_t frames) {
  auto driver = make_fiducial_driver(c, 0);
  std::stop_source stop;
  Result<void> result;
  std::thread t([&] { result = driver->run(sink, stop.get_token()); });
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (sink.raw_count() < frames && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (!result.has_value()) break;
  }
  stop.request_stop();
  t.join();
  return result;
}

// A device table read as the daemon reads devices.cam of dir/test.toml: the source and
// calibration keys, then `more_keys`.
FiducialConfig read_cam_config(const std::string& more_keys, ConfigErrors& errors) {
  auto toml = parse_toml("type = \"fiducial\"\nsource = \"x.png\"\ncalibration = \"c.yml\"\n" + more_keys,
                         "test.toml");
  if (!toml) {
    ADD_FAILURE() << toml.error().message;
    return {};
  }
  TableReader r(*toml, "devices.cam", fiducial_device_spec(), "dir/test.toml", errors);
  return *read_fiducial_config(r, "cam");
}

}  // namespace

TEST(FiducialDriver, ReportsEachMappedTagNearItsTruthWithRawDetections) {
  const Scene s = render_sequence("ok", 5);
  Sink sink;
  auto r = run_driver(config_for(s), sink, 5);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_EQ(sink.raws.size(), 5u);
  ASSERT_EQ(sink.poses.size(), 10u);
  for (const PoseSample& p : sink.poses) {
    const auto& truth = p.sensor == "tag2" ? s.tags[0] : s.tags[1];
    ASSERT_TRUE(p.sensor == "tag2" || p.sensor == "tag9") << p.sensor;
    EXPECT_NE(p.status, TrackingStatus::Lost);
    EXPECT_TRUE(p.covariance.allFinite());
    const Vec6 e = boxminus(truth.T_camera_tag, p.T_parent_child);
    EXPECT_LT(e.dot(p.covariance.ldlt().solve(e)), 30.0) << p.sensor;
    EXPECT_LT(e.head<3>().norm(), 0.02) << p.sensor;
  }
  const auto raw = decode_raw_frame(sink.raws[0].data(), sink.raws[0].size());
  ASSERT_TRUE(raw.has_value());
  ASSERT_EQ(raw->tags.size(), 2u);
  EXPECT_GE(raw->tags[0].solutions.size(), 1u);
  EXPECT_GT(raw->image_noise, 1.0);
  // Truncated records are rejected, not misread.
  EXPECT_FALSE(decode_raw_frame(sink.raws[0].data(), sink.raws[0].size() - 1).has_value());
}

TEST(FiducialDriver, PublishesNoImagesUnlessAsked) {
  const Scene s = render_sequence("noimages", 2);
  Sink sink;
  auto r = run_driver(config_for(s), sink, 2);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_TRUE(sink.images.empty());
}

// Every n-th frame goes out as a JPEG stamped like that frame's poses, so a view of the
// log puts each picture behind the regions measured in it.
TEST(FiducialDriver, PublishesEveryNthFrameWithItsPosesTime) {
  const Scene s = render_sequence("images", 6);
  FiducialConfig c = config_for(s);
  c.publish_images = true;
  c.image_every_n = 2;
  Sink sink;
  auto r = run_driver(c, sink, 6);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_EQ(sink.raws.size(), 6u);
  std::set<std::int64_t> frame_times;
  for (const PoseSample& p : sink.poses) frame_times.insert(p.measurement_time_us);
  ASSERT_EQ(frame_times.size(), 6u);  // one time per frame
  const std::vector<std::int64_t> times(frame_times.begin(), frame_times.end());
  ASSERT_EQ(sink.images.size(), 3u);
  const Camera cam = test::small_camera();
  for (std::size_t i = 0; i < sink.images.size(); ++i) {
    const ImageSample& image = sink.images[i];
    EXPECT_EQ(image.measurement_time_us, times[2 * i]) << "image " << i;
    EXPECT_EQ(image.encoding, "jpeg");
    EXPECT_EQ(image.width, cam.width_px);
    EXPECT_EQ(image.height, cam.height_px);
    const cv::Mat decoded = cv::imdecode(image.bytes, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(decoded.empty()) << "image " << i << " does not decode";
    EXPECT_EQ(decoded.cols, cam.width_px);
    EXPECT_EQ(decoded.rows, cam.height_px);
  }
  // The picture is the rendered scene, JPEG-compressed (mean error 2.2 grey levels here;
  // a differently noised frame of the same scene is 2.9: the times above tell frames apart).
  cv::Mat frame = cv::imread((s.dir / "frame_0000.png").string(), cv::IMREAD_GRAYSCALE);
  cv::Mat first = cv::imdecode(sink.images[0].bytes, cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(first.size(), frame.size());
  EXPECT_LT(cv::norm(first, frame, cv::NORM_L1) / double(frame.total()), 4.0);
}

TEST(FiducialDriver, MissingCameraIsAClearError) {
  const Scene s = render_sequence("cam", 1);
  FiducialConfig c = config_for(s);
  c.source = "63";  // no /dev/video63 here
  Sink sink;
  auto r = run_driver(c, sink, 1);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("cannot open camera 63"), std::string::npos) << r.error().message;
}

TEST(FiducialDriver, UnreadableCalibrationIsAClearError) {
  const Scene s = render_sequence("calib", 1);
  FiducialConfig c = config_for(s);
  std::ofstream(s.dir / "bad.yml") << "%YAML:1.0\n---\nimage_width: [unclosed\n";
  c.calibration = (s.dir / "bad.yml").string();
  Sink sink;
  auto r = run_driver(c, sink, 1);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("bad.yml"), std::string::npos) << r.error().message;
  c.calibration = (s.dir / "absent.yml").string();
  r = run_driver(c, sink, 1);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("absent.yml: calibration file not found"), std::string::npos)
      << r.error().message;
}

TEST(FiducialDriver, CorruptVideoIsAClearError) {
  const Scene s = render_sequence("video", 1);
  FiducialConfig c = config_for(s);
  std::ofstream out(s.dir / "corrupt.avi", std::ios::binary);
  out << "RIFF\x10\x00\x00\x00" << "AVI garbage, not a video at all";
  out.close();
  c.source = (s.dir / "corrupt.avi").string();
  Sink sink;
  auto r = run_driver(c, sink, 1);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("corrupt.avi"), std::string::npos) << r.error().message;
}

TEST(FiducialDriver, ConfigErrorsNameTheKey) {
  ConfigErrors errors;
  const FiducialConfig c = read_cam_config("family = \"tag99\"\n", errors);
  EXPECT_EQ(c.calibration, "dir/c.yml");  // relative to the config file
  const std::string all = errors.joined();
  EXPECT_NE(all.find("unknown AprilTag family 'tag99'"), std::string::npos) << all;
  EXPECT_NE(all.find("devices.cam.tags"), std::string::npos) << all;
}

TEST(FiducialDriver, ImageOptionErrorsNameTheKey) {
  ConfigErrors errors;
  const FiducialConfig c = read_cam_config("publish_images = \"yes\"\nimage_every_n = 0\nimage_jpeg_quality = 101\n"
                                           "[[tags]]\nid = 1\nsize_m = 0.1\n",
                                           errors);
  const std::string all = errors.joined();
  EXPECT_NE(all.find("devices.cam.publish_images"), std::string::npos) << all;
  EXPECT_NE(all.find("devices.cam.image_every_n"), std::string::npos) << all;
  EXPECT_NE(all.find("devices.cam.image_jpeg_quality"), std::string::npos) << all;
  EXPECT_EQ(errors.list().size(), 3u) << all;
  EXPECT_GE(c.image_every_n, 1);  // a usable value even when the key is wrong

  ConfigErrors none;
  const FiducialConfig d = read_cam_config("publish_images = true\nimage_every_n = 5\nimage_jpeg_quality = 60\n"
                                           "[[tags]]\nid = 1\nsize_m = 0.1\n",
                                           none);
  EXPECT_TRUE(none.empty()) << none.joined();
  EXPECT_TRUE(d.publish_images);
  EXPECT_EQ(d.image_every_n, 5);
  EXPECT_EQ(d.image_jpeg_quality, 60);
}

// A bundle is one sensor: its tags are not published unless asked, it is LOST when none
// of them is in view, and its pose is near the truth with a covariance that holds it.
TEST(FiducialDriver, ABundleIsOneSensorItsTagsOnlyWhenAsked) {
  const BundleScene s = render_bundle_sequence("one", 3, 1);
  Sink sink;
  auto r = run_driver(bundle_config_for(s), sink, 3);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  std::map<std::string, std::vector<PoseSample>> by_sensor;
  for (const PoseSample& p : sink.poses) by_sensor[p.sensor].push_back(p);
  ASSERT_EQ(by_sensor.size(), 2u) << "only board and tag9, not the board's tags";
  ASSERT_EQ(by_sensor["board"].size(), 3u);
  ASSERT_EQ(by_sensor["tag9"].size(), 3u);
  for (int f = 0; f < 2; ++f) {
    const PoseSample& p = by_sensor["board"][static_cast<std::size_t>(f)];
    EXPECT_EQ(p.status, TrackingStatus::Ok);
    const Vec6 e = boxminus(s.T_camera_board, p.T_parent_child);
    EXPECT_LT(e.head<3>().norm(), 0.002);
    EXPECT_LT(e.dot(p.covariance.ldlt().solve(e)), 30.0);
  }
  EXPECT_EQ(by_sensor["board"][2].status, TrackingStatus::Lost);
  EXPECT_EQ(sink.details.front(), "");  // nothing to say while all is well

  FiducialConfig c = bundle_config_for(s);
  c.bundles[0].publish_tags = true;
  Sink with_tags;
  r = run_driver(c, with_tags, 1);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  std::set<std::string> sensors;
  for (const PoseSample& p : with_tags.poses) sensors.insert(p.sensor);
  EXPECT_EQ(sensors, (std::set<std::string>{"board", "tag0", "tag1", "tag2", "tag3", "tag9"}));
}

TEST(FiducialDriver, ABundleWhoseTagIsMovedIsDegradedAndSaysWhy) {
  const BundleScene s = render_bundle_sequence("moved", 1, 0, 2);
  Sink sink;
  auto r = run_driver(bundle_config_for(s), sink, 1);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  const auto board = std::find_if(sink.poses.begin(), sink.poses.end(), [](const PoseSample& p) { return p.sensor == "board"; });
  ASSERT_NE(board, sink.poses.end());
  EXPECT_EQ(board->status, TrackingStatus::Degraded);
  ASSERT_EQ(sink.details.size(), 1u);
  EXPECT_EQ(sink.details[0].rfind("board DEGRADED: left out tag 2 is ", 0), 0u) << sink.details[0];
  const Vec6 e = boxminus(s.T_camera_board, board->T_parent_child);
  EXPECT_LT(e.dot(board->covariance.ldlt().solve(e)), 16.8) << "the truth inside the 99% region";
}

TEST(FiducialDriver, BundleConfigIsRead) {
  ConfigErrors errors;
  const FiducialConfig c = read_cam_config(R"(bundle_consistency_chi2 = 30
[[tags]]
id = 9
size_m = 0.08
[[bundles]]
name = "box"
publish_tags = true
[[bundles.tags]]
id = 1
size_m = 0.05
position_m = [0.1, 0, 0]
rotation_rpy_deg = [0, 0, 90]
[[bundles.tags]]
id = 2
size_m = 0.04
orientation_wxyz = [0, 1, 0, 0]
)",
                                           errors);
  ASSERT_TRUE(errors.empty()) << errors.joined();
  EXPECT_EQ(c.bundle_consistency_chi2, 30);
  ASSERT_EQ(c.bundles.size(), 1u);
  const TagBundle& b = c.bundles[0];
  EXPECT_EQ(b.name, "box");
  EXPECT_TRUE(b.publish_tags);
  ASSERT_EQ(b.tags.size(), 2u);
  EXPECT_EQ(b.tags[0].id, 1);
  EXPECT_EQ(b.tags[0].size_m, 0.05);
  EXPECT_TRUE(b.tags[0].T_bundle_tag.translation().isApprox(Vec3(0.1, 0, 0)));
  EXPECT_TRUE(b.tags[0].T_bundle_tag.rotation().isApprox(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix()));
  EXPECT_TRUE(b.tags[1].T_bundle_tag.rotation().isApprox(Eigen::AngleAxisd(M_PI, Vec3::UnitX()).toRotationMatrix()));
  EXPECT_EQ(c.tag_size_m.count(1), 0u);  // a bundle's tag is not in the tag map

  ConfigErrors bundles_only;  // a config with bundles needs no tag map
  read_cam_config("[[bundles]]\nname = \"b\"\n[[bundles.tags]]\nid = 1\nsize_m = 0.05\n", bundles_only);
  EXPECT_TRUE(bundles_only.empty()) << bundles_only.joined();
}

TEST(FiducialDriver, BundleConfigErrorsNameTheKey) {
  ConfigErrors errors;
  read_cam_config(R"([[tags]]
id = 9
size_m = 0.08
[[bundles]]
name = "a"
[[bundles.tags]]
id = 1
size_m = 0
[[bundles.tags]]
id = 2
size_m = 0.05
colour = "red"
orientation_wxyz = [1, 1, 0, 0]
[[bundles.tags]]
id = 3
size_m = 0.05
position_m = [0, 0]
rotation_rpy_deg = [0, 0, 0]
orientation_wxyz = [1, 0, 0, 0]
[[bundles]]
name = "b"
[[bundles.tags]]
id = 3
size_m = 0.05
[[bundles.tags]]
id = 9
size_m = 0.05
[[bundles.tags]]
id = 4
size_m = 0.05
[[bundles.tags]]
id = 4
size_m = 0.05
[[bundles]]
name = "tag9"
tags = []
[[bundles]]
name = "no spaces"
[[bundles.tags]]
id = 5
size_m = 0.05
[[bundles]]
name = "a"
[[bundles.tags]]
id = 6
size_m = 0.05
)",
                  errors);
  const std::string all = errors.joined();
  const auto has = [&](const std::string& what) { return all.find(what) != std::string::npos; };
  EXPECT_TRUE(has("devices.cam.bundles[0].tags[0].size_m: 0 is out of range")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[0].tags[1].colour: unknown key")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[0].tags[1].orientation_wxyz: norm is 1.41")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[0].tags[2].position_m")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[0].tags[2].orientation_wxyz: give orientation_wxyz or rotation_rpy_deg, not both")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[4].name: bundle 'a' is named twice")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[1].tags[0].id: tag 3 is in bundle 'a' already")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[1].tags[1].id: tag 9 is in the tag map ([[tags]]) too")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[1].tags[3].id: tag 4 is listed twice in bundle 'b'")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[2].name: 'tag9' is the sensor name of tag 9")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[2].tags: a bundle needs at least one tag")) << all;
  EXPECT_TRUE(has("devices.cam.bundles[3].name: 'no spaces' is not a sensor name")) << all;
  EXPECT_EQ(errors.list().size(), 12u) << all;
}
