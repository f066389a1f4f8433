// `covtrack view` in its window, on a real X server (Xvfb) whose framebuffer is a file in
// XWD format (-fbdir): the screen, read while the view runs, shows the regions.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

extern char** environ;

namespace {

pid_t spawn(std::vector<std::string> args, const std::vector<std::string>& extra_env = {},
            const posix_spawn_file_actions_t* actions = nullptr) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings(extra_env);
  for (char** e = environ; *e; ++e) env_strings.emplace_back(*e);
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, argv[0], actions, nullptr, argv.data(), envp.data()) != 0) return -1;
  return pid;
}

std::uint32_t big_endian(const std::vector<unsigned char>& b, std::size_t offset) {
  return std::uint32_t(b[offset]) << 24 | std::uint32_t(b[offset + 1]) << 16 |
         std::uint32_t(b[offset + 2]) << 8 | b[offset + 3];
}

struct Screen {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> rgb;  // row-major
};

// An XWD file with 32 bits per pixel (Xvfb's 24-bit depth).
Screen read_xwd(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Screen s;
  if (b.size() < 100) return s;
  const std::uint32_t header = big_endian(b, 0), width = big_endian(b, 16), height = big_endian(b, 20),
                      byte_order = big_endian(b, 28), bits_per_pixel = big_endian(b, 44),
                      bytes_per_line = big_endian(b, 48), colours = big_endian(b, 76);
  const std::size_t data = header + 12 * colours;
  if (bits_per_pixel != 32 || b.size() < data + bytes_per_line * height) return s;
  s.width = int(width), s.height = int(height);
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      const unsigned char* p = &b[data + y * bytes_per_line + 4 * x];
      std::uint32_t v = byte_order == 0 ? (p[0] | p[1] << 8 | p[2] << 16 | std::uint32_t(p[3]) << 24)
                                        : (std::uint32_t(p[0]) << 24 | p[1] << 16 | p[2] << 8 | p[3]);
      s.rgb.push_back({int(v >> 16 & 0xff), int(v >> 8 & 0xff), int(v & 0xff)});
    }
  return s;
}

}  // namespace

TEST(ViewWindow, XvfbScreenShowsTheRegions) {
  const std::filesystem::path fbdir = std::filesystem::temp_directory_path() / ("covtrack_xvfb_" + std::to_string(getpid()));
  std::filesystem::create_directories(fbdir);
  int display_pipe[2];
  ASSERT_EQ(pipe(display_pipe), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclose(&actions, display_pipe[0]);
  const pid_t xvfb = spawn({XVFB, "-displayfd", std::to_string(display_pipe[1]), "-screen", "0", "800x600x24",
                            "-fbdir", fbdir.string(), "-nolisten", "tcp"},
                           {}, &actions);
  posix_spawn_file_actions_destroy(&actions);
  close(display_pipe[1]);
  ASSERT_GT(xvfb, 0) << "cannot start " << XVFB;
  std::string display;
  char c;
  while (read(display_pipe[0], &c, 1) == 1 && c != '\n') display += c;
  close(display_pipe[0]);
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";

  const pid_t view = spawn({COVTRACK_CLI, "view", COVTRACK_SOURCE_DIR "/config/scenes/head_and_world.toml",
                            "--duration", "30"},
                           {"DISPLAY=:" + display});
  ASSERT_GT(view, 0);
  // Poll the screen until the regions are drawn (start-up takes a while on a busy
  // machine), then end the view as a user would (SIGTERM ~ Ctrl-C). Until all three are
  // seen: a screen read mid-frame can hold the green outer regions but not yet the blue
  // ellipses drawn after them (seen once under a parallel ctest: 442 blue pixels).
  struct Counts {
    int green = 0, white = 0, blue = 0;
    bool all_drawn() const { return green > 500 && white > 300 && blue > 500; }
  } counts;
  Screen screen;
  for (int attempt = 0; attempt < 60 && !counts.all_drawn(); ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    screen = read_xwd(fbdir / "Xvfb_screen0");
    counts = {};
    for (const auto& [r, g, b] : screen.rgb) {
      counts.green += g > 150 && r < 90 && b < 90;
      counts.white += r > 240 && g > 240 && b > 240;
      counts.blue += b > 200 && r < 60 && g > 80 && g < 160;
    }
  }
  kill(view, SIGTERM);
  int status = -1;
  waitpid(view, &status, 0);
  kill(xvfb, SIGTERM);
  waitpid(xvfb, nullptr, 0);
  std::filesystem::remove_all(fbdir);

  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "covtrack view failed";
  ASSERT_EQ(screen.width, 800);
  std::printf("screen pixels: outer (green) %d, inner (white) %d, ellipses (blue) %d\n", counts.green,
              counts.white, counts.blue);
  EXPECT_GT(counts.green, 500);
  EXPECT_GT(counts.white, 300);
  EXPECT_GT(counts.blue, 500);
}
