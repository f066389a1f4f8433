// `covtrack view` as a user runs it: headless pictures checked pixel by pixel against the
// regions `covtrack regions --json` reports, a video, a broken background, no display,
// live streams (published by this test inside its private network namespace), and a
// recorded session's camera frames behind the regions.
#include <algorithm>
#include <array>
#include <cstdlib>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <unistd.h>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "golden_image.hpp"
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <covtrack/image_t.hpp>
#include <covtrack/pose_cov_t.hpp>

#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/lcmlog/log_writer.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/pose_message.hpp"

using namespace covtrack::testing;

namespace {

CliRun run(const std::string& args, const std::string& env = "") { return run_covtrack(args, env); }

const std::string kScene = COVTRACK_SOURCE_DIR "/config/scenes/head_and_world.toml";
// One folder per test process: two checkouts running this test at once (a shared
// machine) would otherwise delete each other's scene and log files.
const std::filesystem::path kTmp = [] {
  const auto dir = std::filesystem::temp_directory_path() / ("covtrack_view_cli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}();

struct PixelCounts {
  int green = 0;         // outer-region pixels
  int white = 0;         // inner-region pixels
  int white_astray = 0;  // inner-region pixels outside every outer region
};

bool is_green(const cv::Vec3b& p) { return p[1] > 150 && p[0] < 90 && p[2] < 90; }
bool is_white(const cv::Vec3b& p) { return p[0] > 240 && p[1] > 240 && p[2] > 240; }

PixelCounts count_pixels(const cv::Mat& image, const nlohmann::json& regions) {
  PixelCounts c;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      c.green += is_green(p);
      if (!is_white(p)) continue;
      ++c.white;
      bool in_some_outer = false;
      for (const auto& o : regions["objects"]) in_some_outer = in_some_outer || json_polygon_contains(o["outer_px"], x, y, 2.0);
      c.white_astray += !in_some_outer;
    }
  return c;
}

covtrack::pose_cov_t thing_message(std::int64_t seq, std::int64_t time_us, bool lost) {
  covtrack::pose_cov_t m{};
  m.device = "viewtest";
  m.sensor = "thing";
  m.parent_frame = "camera";
  m.child_frame = "thing";
  m.sequence = seq;
  m.measurement_time_us = m.publish_time_us = time_us;
  covtrack::Pose T = covtrack::Pose::Identity();
  T.translation() = covtrack::Vec3(0, 0, 2);
  covtrack::Mat6 C = covtrack::Mat6::Zero();
  C.diagonal() << 4e-6, 4e-6, 4e-6, 2.5e-5, 2.5e-5, 2.5e-5;
  covtrack::set_pose(m, T, C);
  m.status = lost ? covtrack::pose_cov_t::STATUS_LOST : covtrack::pose_cov_t::STATUS_OK;
  if (lost) {
    for (int i = 0; i < 36; i += 7) m.covariance[i] = std::numeric_limits<double>::infinity();
  }
  return m;
}

// A scene whose only object, 2 m ahead of the camera, hangs on the stream viewtest/thing.
std::filesystem::path write_thing_scene() {
  const std::filesystem::path scene = kTmp / "covtrack_thing_scene.toml";
  std::ofstream(scene) << "[camera]\nframe = \"camera\"\ncalibration = \"" COVTRACK_SOURCE_DIR
                          "/config/cameras/example_640x480.yml\"\n"
                          "[[transform]]\nparent = \"camera\"\nchild = \"thing\"\nposition_m = [0, 0, 2]\n"
                          "sigma_m = [0.002, 0.002, 0.002]\nsigma_rad = [0.005, 0.005, 0.005]\n"
                          "stream = \"viewtest/thing\"\n"
                          "[[object]]\nname = \"thing\"\nframe = \"thing\"\nbox_m = [0.4, 0.3, 0.01]\n";
  return scene;
}

int green_pixels_of(const std::string& args) {
  const std::string png = (kTmp / "covtrack_view_green.png").string();
  const CliRun r = run("view " + args + " --png " + png);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const cv::Mat image = cv::imread(png, cv::IMREAD_COLOR);
  int green = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) green += is_green(image.at<cv::Vec3b>(y, x));
  std::filesystem::remove(png);
  return green;
}

}  // namespace

TEST(ViewCli, PictureShowsInnerRegionsInsideOuterRegions) {
  const std::string png = (kTmp / "covtrack_view_test.png").string();
  const CliRun view = run("view " + kScene + " --png " + png);
  ASSERT_EQ(view.exit_code, 0) << view.out;
  const CliRun regions = run("regions " + kScene + " --json");
  ASSERT_EQ(regions.exit_code, 0) << regions.out;
  const cv::Mat image = cv::imread(png, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 640);
  const PixelCounts c = count_pixels(image, nlohmann::json::parse(regions.out));
  std::printf("pixels: outer %d, inner %d, inner outside every outer %d\n", c.green, c.white, c.white_astray);
  EXPECT_GT(c.green, 500);
  EXPECT_GT(c.white, 300);
  EXPECT_EQ(c.white_astray, 0);
  std::filesystem::remove(png);
}

// Selection with a user, scripted (the window's mouse and keys drive the same session):
// a click on one crate selects it and outlines it in orange; a click where both crates
// may be lays out a target each, and a click on a target picks its crate; direct
// selection picks at once; a click that cannot be read is a usage error.
TEST(ViewCli, ScriptedClicksSelectTheIntendedCrate) {
  const auto crates = write_crates_scene(kTmp);
  ASSERT_TRUE(crates) << "the crates' regions, overlapping";
  const std::string png = (kTmp / "covtrack_view_selection.png").string();
  const std::string view = "view " + crates->path + " --png " + png + " --duration 1";
  CliRun r = run(view + " --click " + crates->left_middle_px + "@0.1 --click " + crates->in_both_px +
                 "@0.2 --click target:right_crate@0.3");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("selected left_crate (two-step)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("targets: pick one of 2: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("selected right_crate (two-step)"), std::string::npos) << r.out;
  EXPECT_LT(r.out.find("selected left_crate"), r.out.find("targets:")) << "in the order clicked: " << r.out;
  // The picture, taken after the last click: the right crate's outline is orange, the
  // left crate's is not.
  const cv::Mat image = cv::imread(png, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  int orange_left = 0, orange_right = 0;
  const nlohmann::json& objects = crates->regions["objects"];
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);  // BGR
      if (p[0] > 40 || p[1] < 120 || p[1] > 180 || p[2] < 220) continue;
      orange_left += json_polygon_contains(objects[0]["outer_px"], x, y, 1) &&
                     !json_polygon_contains(objects[1]["outer_px"], x, y, 1);
      orange_right += json_polygon_contains(objects[1]["outer_px"], x, y, 1) &&
                      !json_polygon_contains(objects[0]["outer_px"], x, y, 1);
    }
  std::printf("orange pixels: left crate alone %d, right crate alone %d\n", orange_left, orange_right);
  EXPECT_GT(orange_right, 300);
  EXPECT_LT(orange_left, 10);  // anti-aliased edges of other colours can blend into orange's range

  r = run(view + " --selection direct --click " + crates->in_both_px + "@0.1 --click target:left_crate@0.2");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("(direct)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("targets:"), std::string::npos) << "direct selection lays out no targets: " << r.out;
  EXPECT_NE(r.out.find("no target of 'left_crate' is shown"), std::string::npos) << r.out;

  r = run(view + " --click pointer@0.1");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("the scene has no tracked pointer"), std::string::npos) << r.out;

  r = run(view + " --click 12@0.1");
  EXPECT_EQ(r.exit_code, 2) << r.out;  // a usage error
  EXPECT_NE(r.out.find("expected U,V@T"), std::string::npos) << r.out;
  std::filesystem::remove(png);
}

// The tool-box demo 4.5 s into its loop (shaded regions, leader lines, the pointer between
// drawers with its targets), against a reviewed picture. Offline frames are rendered at
// their scene times, so the picture is the same on every run; the tolerance covers
// anti-aliasing differences, not a moved region or label.
// To accept a deliberate change: COVTRACK_UPDATE_GOLDEN=1 build/tests/tools/view_cli_test
TEST(ViewCli, ToolBoxFrameMatchesTheGoldenImage) {
  const std::string golden = COVTRACK_SOURCE_DIR "/tests/tools/golden/toolbox_4.5s.png";
  const std::string png = (kTmp / "covtrack_view_toolbox.png").string();
  const CliRun view = run("view " COVTRACK_SOURCE_DIR "/config/scenes/toolbox.toml --png " + png + " --duration 4.5");
  ASSERT_EQ(view.exit_code, 0) << view.out;
  const auto fraction = golden_difference(png, golden);
  ASSERT_TRUE(fraction) << "cannot compare " << png << " with " << golden;
  std::printf("golden: %.3f%% of the pixels differ by more than 48 levels\n", 100 * *fraction);
  EXPECT_LT(*fraction, 0.002);
  std::filesystem::remove(png);
}

// The codec a browser needs, read from the file itself: an .mp4's avcC box (H.264, and a
// profile browsers decode: Baseline 66, Main 77 or High 100, all 4:2:0), a .webm's codec ID.
std::string codec_in_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.substr(4, 4) == "ftyp") {
    const auto avcc = bytes.find("avcC");
    if (avcc == std::string::npos || avcc + 6 > bytes.size()) return "mp4 without H.264";
    const int profile = static_cast<unsigned char>(bytes[avcc + 5]);
    return profile == 66 || profile == 77 || profile == 100 ? "H.264" : "H.264 profile " + std::to_string(profile);
  }
  if (bytes.starts_with("\x1a\x45\xdf\xa3") && bytes.find("webm") != std::string::npos)
    return bytes.find("V_VP9") != std::string::npos ? "VP9" : "webm without VP9";
  return "neither mp4 nor webm";
}

int frames_in(const std::string& path) {
  cv::VideoCapture video(path, cv::CAP_FFMPEG);
  if (!video.isOpened()) return -1;
  int frames = 0;
  for (cv::Mat frame; video.read(frame);) {
    ++frames;
    EXPECT_EQ(frame.cols, 640);
  }
  return frames;
}

TEST(ViewCli, VideoHasTheFramesAsked) {
  const std::string mp4 = (kTmp / "covtrack_view_test.mp4").string();
  const CliRun r = run("view " + kScene + " --video " + mp4 + " --duration 1 --fps 10");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(codec_in_file(mp4), "H.264");
  const int frames = frames_in(mp4);
  EXPECT_GE(frames, 10);
  EXPECT_LE(frames, 11);
  std::filesystem::remove(mp4);
  const CliRun avi = run("view " + kScene + " --video " + (kTmp / "x.avi").string());
  EXPECT_EQ(avi.exit_code, 2) << avi.out;
  EXPECT_NE(avi.out.find(".webm (VP9)"), std::string::npos) << avi.out;
}

// A video of a recorded session covers the whole session (19.5 s; it stopped at 10 s), in
// both formats.
TEST(ViewCli, VideoOfALogCoversAllOfIt) {
  const std::string log = COVTRACK_SOURCE_DIR "/tests/data/lenz_session.lcm";
  auto reader = covtrack::lcmlog::LogReader::open(log);
  ASSERT_TRUE(reader);
  std::int64_t first = -1, last = 0;
  while (auto e = reader->next()) {
    if (first < 0) first = e->timestamp_us;
    last = e->timestamp_us;
  }
  const double fps = 4;
  const double expected = (last - first) * 1e-6 * fps;
  for (const std::string name : {"session.mp4", "session.webm"}) {
    const std::string path = (kTmp / name).string();
    const CliRun r = run("view " + kScene + " --log " + log + " --video " + path + " --fps 4");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(codec_in_file(path), name.ends_with("mp4") ? "H.264" : "VP9");
    const int frames = frames_in(path);
    std::printf("%s: %d frames, the log's duration x fps = %.1f\n", name.c_str(), frames, expected);
    EXPECT_NEAR(frames, expected, 2);
    std::filesystem::remove(path);
  }
}

TEST(ViewCli, CorruptBackgroundIsReportedAndTheViewGoesOnButAMissingCameraEndsIt) {
  const std::string bad = (kTmp / "covtrack_corrupt.avi").string();
  std::ofstream(bad) << "RIFF\x10\0\0\0AVI garbage that is no video at all";
  const std::string png = (kTmp / "covtrack_view_bg.png").string();
  const CliRun r = run("view " + kScene + " --png " + png + " --background " + bad);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find(bad), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(png));
  const CliRun camera = run("view " + kScene + " --png " + png + " --background camera:57");
  EXPECT_EQ(camera.exit_code, 1) << camera.out;  // a camera asked for and missing ends the view
  EXPECT_NE(camera.out.find("camera:57"), std::string::npos) << camera.out;
  std::filesystem::remove(bad);
  std::filesystem::remove(png);
}

TEST(ViewCli, NoDisplayAndNoFileOutputIsAClearError) {
  const CliRun r = run("view " + kScene, "env -u DISPLAY");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("--png"), std::string::npos) << r.out;
}

// A stream this test publishes: the object is on screen only while the stream reports
// (the scene's value is not used with --live).
TEST(ViewCli, LiveStreamsDriveTheRegions) {
  const std::filesystem::path scene = write_thing_scene();
  lcm::LCM lcm;
  ASSERT_TRUE(lcm.good());
  std::atomic<bool> stop{false}, lost{false};
  std::thread publisher([&] {
    for (std::int64_t seq = 0; !stop; ++seq) {
      const covtrack::pose_cov_t m = thing_message(seq, covtrack::now_us(), lost);
      lcm.publish(covtrack::pose_channel("viewtest", "thing"), &m);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  const std::string args = scene.string() + " --live --duration 1.5";
  const int reporting = green_pixels_of(args);
  lost = true;
  const int lost_stream = green_pixels_of(args);
  stop = true;
  publisher.join();
  std::printf("outer-region pixels: stream reporting %d, stream LOST %d\n", reporting, lost_stream);
  EXPECT_GT(reporting, 300);
  EXPECT_EQ(lost_stream, 0);
  std::filesystem::remove(scene);
}

// A recorded session: one second of reports, then one second LOST. The view follows the
// log's time, so a picture at 0.5 s shows the object and one at 1.6 s does not.
TEST(ViewCli, LogIsFollowedAtItsOwnTime) {
  const std::filesystem::path scene = write_thing_scene();
  const std::string log_path = (kTmp / "covtrack_view_session.lcm").string();
  {
    auto log = covtrack::lcmlog::LogWriter::create(log_path, true);
    ASSERT_TRUE(log) << log.error().message;
    const std::int64_t t0 = 1'700'000'000'000'000;
    for (int i = 0; i < 100; ++i) {
      const std::int64_t t = t0 + i * 20'000;
      const covtrack::pose_cov_t m = thing_message(i, t, i >= 50);
      std::vector<std::byte> bytes(m.getEncodedSize());
      m.encode(bytes.data(), 0, int(bytes.size()));
      ASSERT_TRUE(log->write(t, covtrack::pose_channel("viewtest", "thing"), bytes));
    }
  }
  const int early = green_pixels_of(scene.string() + " --log " + log_path + " --duration 0.5");
  const int late = green_pixels_of(scene.string() + " --log " + log_path + " --duration 0.8 --speed 2");
  std::printf("outer-region pixels: log at 0.5 s %d, at 1.6 s %d\n", early, late);
  EXPECT_GT(early, 300);
  EXPECT_EQ(late, 0);

  const CliRun missing = run("view " + scene.string() + " --log /nonexistent/session.lcm --png /tmp/x.png");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.out.find("/nonexistent/session.lcm"), std::string::npos) << missing.out;
  std::filesystem::remove(log_path);
  std::filesystem::remove(scene);
}

// One damaged byte inside a pose event (a string length of 0 or -1, a fingerprint) made
// `covtrack view --log` abort in LCM's decoder: now each is counted and the rest is used.
TEST(ViewCli, CorruptPoseEventsOfALogAreCountedAndTheRestUsed) {
  const std::filesystem::path scene = write_thing_scene();
  const std::string log_path = (kTmp / "covtrack_view_corrupt.lcm").string();
  {
    auto log = covtrack::lcmlog::LogWriter::create(log_path, true);
    ASSERT_TRUE(log) << log.error().message;
    const std::int64_t t0 = 1'700'000'000'000'000;
    for (int i = 0; i < 50; ++i) {
      const std::int64_t t = t0 + i * 20'000;
      const covtrack::pose_cov_t m = thing_message(i, t, false);
      std::vector<std::byte> bytes(m.getEncodedSize());
      m.encode(bytes.data(), 0, int(bytes.size()));
      const std::size_t device_length_at = 8 + 24;
      if (i == 10) bytes[device_length_at + 3] = std::byte{0};                               // length 0
      if (i == 11) std::fill_n(bytes.begin() + device_length_at, 4, std::byte{0xff});        // length -1
      if (i == 12) bytes[3] ^= std::byte{0x10};                                              // fingerprint
      ASSERT_TRUE(log->write(t, covtrack::pose_channel("viewtest", "thing"), bytes));
    }
  }
  const std::string png = (kTmp / "covtrack_view_corrupt.png").string();
  const CliRun r = run("view " + scene.string() + " --log " + log_path + " --duration 0.5 --png " + png);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("rejected pose messages of the log: 3 (bad length 2, wrong type 1)"), std::string::npos)
      << r.out;
  const cv::Mat image = cv::imread(png, cv::IMREAD_COLOR);
  int green = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) green += is_green(image.at<cv::Vec3b>(y, x));
  EXPECT_GT(green, 300);  // the good reports around them drive the regions
  std::filesystem::remove(png);
  std::filesystem::remove(log_path);
  std::filesystem::remove(scene);
}

namespace {

// A solid-colour camera frame as the fiducial driver publishes it (smaller than the view,
// so the view must scale it).
covtrack::image_t solid_image(const cv::Vec3b& bgr, const std::string& encoding) {
  const cv::Mat frame(240, 320, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2]));
  covtrack::image_t m{};
  m.device = "viewtest";
  m.width = frame.cols;
  m.height = frame.rows;
  m.encoding = encoding;
  EXPECT_TRUE(cv::imencode(encoding == "png" ? ".png" : ".jpg", frame, m.data));
  m.size = static_cast<std::int32_t>(m.data.size());
  return m;
}

template <typename Msg>
void write_event(covtrack::lcmlog::LogWriter& log, std::int64_t t, const std::string& channel, Msg m) {
  std::vector<std::byte> bytes(m.getEncodedSize());
  m.encode(bytes.data(), 0, int(bytes.size()));
  ASSERT_TRUE(log.write(t, channel, bytes));
}

// Pixels far from the object and the legend: where only the background shows.
bool background_is(const cv::Mat& image, const cv::Vec3b& bgr) {
  for (const cv::Point p : {cv::Point(630, 10), cv::Point(630, 240), cv::Point(500, 120)}) {
    const cv::Vec3b v = image.at<cv::Vec3b>(p);
    for (int c = 0; c < 3; ++c)
      if (std::abs(int(v[c]) - int(bgr[c])) > 6) return false;
  }
  return true;
}

}  // namespace

// A session with camera frames: the view draws the latest frame at or before the log time
// behind the regions; a corrupt frame is reported and skipped; --background still wins.
TEST(ViewCli, LogCameraFramesAreTheBackground) {
  const std::filesystem::path scene = write_thing_scene();
  const std::string log_path = (kTmp / "covtrack_view_images.lcm").string();
  const cv::Vec3b first(200, 30, 30), second(30, 160, 220);
  const std::int64_t t0 = 1'700'000'000'000'000;
  {
    auto log = covtrack::lcmlog::LogWriter::create(log_path, true);
    ASSERT_TRUE(log) << log.error().message;
    const std::string image_channel = covtrack::image_channel("viewtest");
    for (int i = 0; i < 300; ++i) {  // 6 s of reports
      const std::int64_t t = t0 + i * 20'000;
      write_event(*log, t, covtrack::pose_channel("viewtest", "thing"), thing_message(i, t, false));
      if (i == 0) write_event(*log, t, image_channel, solid_image(first, "png"));
      if (i == 100) {  // at 2 s: a frame whose bytes are no JPEG
        covtrack::image_t bad = solid_image(second, "jpeg");
        std::fill(bad.data.begin(), bad.data.end(), 0x55);
        write_event(*log, t, image_channel, bad);
      }
      if (i == 200) write_event(*log, t, image_channel, solid_image(second, "jpeg"));  // at 4 s
    }
  }
  const std::string png = (kTmp / "covtrack_view_images.png").string();
  const auto picture = [&](const std::string& timing, std::string* out = nullptr) {
    const CliRun r = run("view " + scene.string() + " --log " + log_path + " " + timing + " --png " + png);
    EXPECT_EQ(r.exit_code, 0) << r.out;
    if (out) *out = r.out;
    cv::Mat image = cv::imread(png, cv::IMREAD_COLOR);
    std::filesystem::remove(png);
    return image;
  };
  const cv::Mat at_half_second = picture("--duration 0.5");
  std::string corrupt_out;
  const cv::Mat at_3s = picture("--duration 1.5 --speed 2", &corrupt_out);
  const cv::Mat at_end = picture("--duration 2 --speed 20");
  const cv::Mat overridden = picture("--duration 2 --speed 20 --background \"#00ff00\"");
  ASSERT_FALSE(at_half_second.empty());
  ASSERT_FALSE(at_3s.empty());
  ASSERT_FALSE(at_end.empty());
  ASSERT_FALSE(overridden.empty());
  EXPECT_TRUE(background_is(at_half_second, first)) << at_half_second.at<cv::Vec3b>(10, 630);
  EXPECT_TRUE(background_is(at_3s, first)) << at_3s.at<cv::Vec3b>(10, 630);  // the corrupt one skipped
  EXPECT_NE(corrupt_out.find("skipped"), std::string::npos) << corrupt_out;
  EXPECT_TRUE(background_is(at_end, second)) << at_end.at<cv::Vec3b>(10, 630);
  EXPECT_TRUE(background_is(overridden, cv::Vec3b(0, 255, 0))) << overridden.at<cv::Vec3b>(10, 630);
  std::filesystem::remove(log_path);
  std::filesystem::remove(scene);
}
