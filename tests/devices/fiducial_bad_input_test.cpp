// The fiducial driver on bad input, with real rendered frames and real files: a cut
// JPEG or PNG in an image sequence is reported by name and skipped while the frames
// around it are processed; a camera that sees no tag says so instead of looking as if it
// never started; a looped sequence runs at its configured rate, counted from the frames'
// own timestamps (on a simulated clock, so that a loaded machine cannot slow it down).
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "covtrack/devices/fiducial/fiducial_driver.hpp"
#include "covtrack/emulators/fiducial/tag_renderer.hpp"
#include "fiducial_config.hpp"
#include "fiducial_scene.hpp"
#include "manual_clock.hpp"
#include "raw_detection.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
namespace fs = std::filesystem;

namespace {

// Keeps what the driver reports; tests wait on it for an event, not for a time.
class EventSink : public SampleSink {
 public:
  void pose(const PoseSample& s) override { add([&] { poses.push_back(s); }); }
  void truth(const TruthSample&) override {}
  void raw(ByteDirection, const std::uint8_t* d, std::size_t n) override {
    auto frame = decode_raw_frame(d, n);
    ASSERT_TRUE(frame.has_value());
    add([&] { frames.push_back(*frame); });
  }
  void running(const std::string& detail) override {
    add([&] { if (details.empty() || details.back() != detail) details.push_back(detail); });
  }
  void count_error(const std::string& what) override { add([&] { errors.push_back(what); }); }
  void count_resync() override {}
  void count_drop() override {}

  // Waits until `done()` holds (under the lock) or 60 s passed; returns done().
  template <typename Done>
  bool wait_for(Done done) {
    std::unique_lock l(m);
    return cv.wait_for(l, std::chrono::seconds(60), done);
  }

  std::mutex m;
  std::condition_variable cv;
  std::vector<PoseSample> poses;
  std::vector<RawFrame> frames;
  std::vector<std::string> details, errors;

 private:
  template <typename F>
  void add(F f) {
    { std::lock_guard l(m); f(); }
    cv.notify_all();
  }
};

// The driver on its own thread until the test is done with it, on `clock` (which it
// joins) if given, else on the real clock.
class RunningDriver {
 public:
  RunningDriver(const FiducialConfig& c, EventSink& sink, test::ManualClock* clock = nullptr)
      : driver_(clock ? make_fiducial_driver(c, 0, *clock) : make_fiducial_driver(c, 0)) {
    if (clock) clock->join();
    thread_ = std::thread([this, &sink, clock] {
      result_ = driver_->run(sink, stop_.get_token());
      if (clock) clock->leave();
    });
  }
  Result<void> stop() {
    stop_.request_stop();
    thread_.join();
    return result_;
  }
  ~RunningDriver() {
    if (thread_.joinable()) stop();
  }

 private:
  std::unique_ptr<Driver> driver_;
  std::stop_source stop_;
  Result<void> result_;
  std::thread thread_;
};

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / fmt::format("fiducial_bad_{}_{}", name, getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

const std::vector<RenderedTag> kTags = {{2, 0.1, test::tag_pose(0.8, 25, 10, 30, -0.1, 0)},
                                        {9, 0.1, test::tag_pose(1.0, -20, -5, 60, 0.15, 0.05)}};

// dir/frame_NNNN.ext, one per entry of `views` (the tags in that frame), and dir/camera.yml.
fs::path write_frames(const fs::path& dir, const std::string& ext,
                      const std::vector<std::vector<RenderedTag>>& views) {
  const Camera cam = test::small_camera();
  EXPECT_TRUE(save_camera(cam, dir / "camera.yml").has_value());
  auto family = TagFamily::open("tag36h11");
  std::mt19937_64 rng(5);
  for (std::size_t i = 0; i < views.size(); ++i) {
    const cv::Mat frame = add_sensor_noise(render_tags(cam, **family, views[i], RenderLook{}), 2, rng);
    EXPECT_TRUE(cv::imwrite((dir / fmt::format("frame_{:04d}{}", i, ext)).string(), frame));
  }
  return dir / fmt::format("frame_%04d{}", ext);
}

FiducialConfig config_for(const fs::path& pattern) {
  FiducialConfig c;
  c.device = "cam";
  c.source = pattern.string();
  c.calibration = (pattern.parent_path() / "camera.yml").string();
  c.detector.decimate = 1;
  c.rate_hz = 0;
  c.loop = false;
  c.tag_size_m = {{2, 0.1}, {9, 0.1}};
  return c;
}

// Runs the driver on the files of `pattern` until `done` holds (under the sink's lock);
// returns whether it did. The driver must stop cleanly.
template <typename Done>
bool run_until(EventSink& sink, const fs::path& pattern, Done done) {
  RunningDriver driver(config_for(pattern), sink);
  const bool reached = sink.wait_for(done);
  auto result = driver.stop();
  EXPECT_TRUE(result.has_value()) << result.error().message;
  return reached;
}

void cut_to_half(const fs::path& file) {
  fs::resize_file(file, fs::file_size(file) / 2);
}

}  // namespace

class DamagedFrame : public ::testing::TestWithParam<std::string> {};

// Frame 2 of 5 is cut to half its bytes. It is reported once, by file name, and not
// processed; frames 0, 1, 3 and 4 are, each with both tags. (Without the check a cut
// JPEG is processed with its lower half grey, and a cut PNG ended the sequence there.)
TEST_P(DamagedFrame, IsNamedAndSkippedAndTheFramesAroundItAreProcessed) {
  const std::string ext = GetParam();
  const fs::path dir = fresh_dir("cut" + ext.substr(1));
  const fs::path pattern = write_frames(dir, ext, std::vector<std::vector<RenderedTag>>(5, kTags));
  cut_to_half(dir / ("frame_0002" + ext));
  EventSink sink;
  // The frame index counts every frame read, so index 4 is the last file's.
  ASSERT_TRUE(run_until(sink, pattern, [&] { return !sink.frames.empty() && sink.frames.back().frame == 4; }))
      << "the last frame was never processed";
  std::vector<std::uint32_t> processed;
  for (const RawFrame& f : sink.frames) {
    processed.push_back(f.frame);
    EXPECT_EQ(f.tags.size(), 2u) << "frame " << f.frame;
  }
  EXPECT_EQ(processed, (std::vector<std::uint32_t>{0, 1, 3, 4}));
  ASSERT_EQ(sink.errors.size(), 1u);
  const std::string& error = sink.errors[0];
  EXPECT_NE(error.find("damaged frame '" + (dir / ("frame_0002" + ext)).string() + "'"), std::string::npos) << error;
  EXPECT_NE(error.find(ext == ".jpg" ? "truncated JPEG" : "truncated PNG"), std::string::npos) << error;
  EXPECT_EQ(sink.poses.size(), 8u);
}

INSTANTIATE_TEST_SUITE_P(JpegAndPng, DamagedFrame, ::testing::Values(".jpg", ".png"),
                         [](const auto& info) { return info.param.substr(1); });

// Frames without tags, then one with a tag outside the map, then the mapped tags: the
// detail follows what the camera sees, and is cleared once a mapped tag is posed.
TEST(NoTagInView, IsReportedAsRunningWithADetail) {
  const fs::path dir = fresh_dir("notag");
  const RenderedTag unmapped{5, 0.1, test::tag_pose(0.9, 10, 0, 0)};
  const fs::path pattern = write_frames(dir, ".png", {{}, {}, {unmapped}, kTags});
  EventSink sink;
  ASSERT_TRUE(run_until(sink, pattern, [&] { return sink.frames.size() == 4; }));
  const std::vector<std::string> expected = {"no tag in view",
                                             "no mapped tag in view (seen, not in the tag map: 5)", ""};
  EXPECT_EQ(sink.details, expected);
  EXPECT_TRUE(sink.errors.empty());
}

// Two prints of tag 2 in one frame, beside tag 9: the copy is reported by id and frame,
// not dropped in silence, and the first is still posed (with tag 9).
TEST(DuplicateTagId, IsReportedByIdAndFrame) {
  const fs::path dir = fresh_dir("duplicate");
  const RenderedTag copy{2, 0.1, test::tag_pose(0.9, 0, 0, 0, 0.18, -0.1)};
  const fs::path pattern = write_frames(dir, ".png", {{kTags[0], kTags[1], copy}});
  EventSink sink;
  ASSERT_TRUE(run_until(sink, pattern, [&] { return sink.frames.size() == 1; }));
  ASSERT_EQ(sink.errors.size(), 1u);
  EXPECT_NE(sink.errors[0].find("tag 2 detected 2 times in frame 0"), std::string::npos) << sink.errors[0];
  EXPECT_EQ(sink.details, std::vector<std::string>{""}) << "the mapped tags are still posed";
}

// One still frame looped at 20 Hz: 40 frame periods must span 2 s of the frames' own
// measurement times. (Starting over used to cost a period: every other period was
// spent on the wrap, and this source ran at 10 Hz.) On a simulated clock that moves in
// steps dividing the period, a paced driver wakes exactly on its schedule, so the rate
// is exact; decoding and detection take no simulated time.
TEST(LoopedSequence, RunsAtTheConfiguredRate) {
  for (const int count : {1, 3}) {
    const fs::path dir = fresh_dir(fmt::format("loop{}", count));
    const fs::path pattern = write_frames(dir, ".png", std::vector<std::vector<RenderedTag>>(count, kTags));
    FiducialConfig c = config_for(pattern);
    c.rate_hz = 20;
    c.loop = true;
    test::ManualClock clock;
    EventSink sink;
    RunningDriver driver(c, sink, &clock);
    const bool done = clock.run_until(
        [&] {
          std::lock_guard l(sink.m);
          return sink.frames.size() >= 41;
        },
        std::chrono::seconds(10));
    auto result = driver.stop();
    ASSERT_TRUE(result.has_value()) << result.error().message;
    ASSERT_TRUE(done);
    const double span_s = (sink.frames[40].time_us - sink.frames[0].time_us) * 1e-6;
    const double rate_hz = 40 / span_s;
    std::printf("%d-frame loop: 40 periods in %.3f s, %.2f Hz\n", count, span_s, rate_hz);
    EXPECT_NEAR(rate_hz, 20.0, 1e-9) << count << "-frame loop";
    EXPECT_EQ(sink.frames[40].frame, 40u);  // every period read a frame
  }
}
