// The fiducial driver on rendered image sequences: poses near the truth with finite
// covariances, decodable raw detections, the frames themselves when asked (publish_images),
// and clear errors for a missing camera, an unreadable calibration and a corrupt video.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "covtrack/devices/fiducial/fiducial_config.hpp"
#include "covtrack/devices/fiducial/fiducial_driver.hpp"
#include "covtrack/devices/fiducial/raw_detection.hpp"
#include "covtrack/devices/fiducial/tag_renderer.hpp"
#include "fiducial_scene.hpp"

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
  std::size_t raw_count() { std::lock_guard l(m); return raws.size(); }
  std::mutex m;
  std::vector<PoseSample> poses;
  std::vector<std::vector<std::uint8_t>> raws;
  std::vector<ImageSample> images;
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
  const CameraModel cam = test::small_camera();
  EXPECT_TRUE(save_camera_model(cam, s.dir / "camera.yml").has_value());
  auto family = TagFamily::open("tag36h11");
  s.tags = {{2, 0.1, test::tag_pose(0.8, 25, 10, 30, -0.1, 0)},
            {9, 0.1, test::tag_pose(1.0, -20, -5, 60, 0.15, 0.05)}};
  const cv::Mat clean = render_tags(cam, **family, s.tags, RenderLook{});
  std::mt19937_64 rng(3);
  for (int f = 0; f < frames; ++f)
    cv::imwrite((s.dir / fmt::format("frame_{:04d}.png", f)).string(), add_sensor_noise(clean, 3, rng));
  return s;
}

FiducialConfig config_for(const Scene& s) {
  FiducialConfig c;
  c.device = "cam";
  c.source = (s.dir / "frame_%04d.png").string();
  c.calibration = (s.dir / "camera.yml").string();
  c.detector.decimate = 1;
  c.rate_hz = 0;
  c.loop = false;
  c.tag_size_m = {{2, 0.1}, {9, 0.1}};
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
  return read_fiducial_config(r, "cam");
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
  const CameraModel cam = test::small_camera();
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
