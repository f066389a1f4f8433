// A calibration file read in a child process (protocol/camera/src/isolated_read.hpp): the
// camera comes back whole, an error comes back as it was, a reader that loops forever is
// stopped at the limit and one that crashes is reported, the caller carrying on each time.
// And the file that made it necessary: OpenCV 4.6 loops forever on it.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>

#include "covtrack/protocol/camera.hpp"
#include "isolated_read.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

TEST(IsolatedRead, TheCameraComesBackWhole) {
  Camera c;
  c.fx = 501.5, c.fy = 502.25, c.cx = 319.125, c.cy = 241.0625, c.width_px = 640, c.height_px = 480;
  c.k1 = -0.25, c.k2 = 0.125, c.p1 = 1e-3, c.p2 = -2e-3, c.k3 = 0.0625;
  c.intrinsic_sigmas_px = Eigen::Vector4d(1.5, 1.25, 0.75, 0.5);
  const auto got = read_isolated([&] { return Result<Camera>(c); }, "cam.yml");
  ASSERT_TRUE(got) << got.error().message;
  EXPECT_EQ(got->width_px, 640);
  EXPECT_EQ(got->height_px, 480);
  for (const auto& [a, b] : {std::pair{got->fx, c.fx}, {got->fy, c.fy}, {got->cx, c.cx}, {got->cy, c.cy},
                             {got->k1, c.k1}, {got->k2, c.k2}, {got->p1, c.p1}, {got->p2, c.p2}, {got->k3, c.k3}})
    EXPECT_EQ(a, b);
  EXPECT_EQ(got->intrinsic_sigmas_px, c.intrinsic_sigmas_px);
}

TEST(IsolatedRead, AnErrorComesBackAsItWas) {
  const auto got = read_isolated([] { return Result<Camera>(fail("cam.yml: key 'camera_matrix' is missing")); }, "cam.yml");
  ASSERT_FALSE(got);
  EXPECT_EQ(got.error().message, "cam.yml: key 'camera_matrix' is missing");
}

TEST(IsolatedRead, AReaderThatNeverEndsIsStoppedAtTheLimit) {
  const auto start = std::chrono::steady_clock::now();
  const auto got = read_isolated(
      [] {
        for (volatile bool forever = true; forever;) {
        }
        return Result<Camera>(Camera{});
      },
      "cam.yml", 300ms);
  ASSERT_FALSE(got);
  EXPECT_NE(got.error().message.find("did not finish within 0.3 s"), std::string::npos) << got.error().message;
  EXPECT_GE(std::chrono::steady_clock::now() - start, 300ms);
}

TEST(IsolatedRead, AReaderThatCrashesIsReported) {
  const auto got = read_isolated([] {
    std::raise(SIGSEGV);
    return Result<Camera>(Camera{});
  }, "cam.yml");
  ASSERT_FALSE(got);
  EXPECT_NE(got.error().message.find("crashed on it (signal 11)"), std::string::npos) << got.error().message;
}

// Found by fuzzing the calibration reader: an indented map, "--", then "-0" at the left.
TEST(IsolatedRead, TheFileOpenCVLoopsForeverOnIsAnErrorAfterTheLimit) {
  const auto path = std::filesystem::temp_directory_path() / "covtrack_cam_opencv_loops.yml";
  std::ofstream(path) << "%YAML:1.0\n---\n  a: 1\n--\n-0";
  const auto got = load_camera(path);
  ASSERT_FALSE(got);
  EXPECT_NE(got.error().message.find(path.string() + ": OpenCV's reader did not finish within 10 s"), std::string::npos)
      << got.error().message;
}
