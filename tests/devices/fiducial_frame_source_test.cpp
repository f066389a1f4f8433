// The fiducial driver's frame sources on real files written by OpenCV: a JPEG or PNG cut
// short is reported as damaged (named, not decoded half grey) and the files around it
// still read; a looped sequence starts over within one read; a source that cannot be
// opened says what it was taken for and where it was looked for; a FIFO where a file
// should be is refused for its kind, never opened (the open would block the driver).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "frame_source.hpp"
#include "image_file_check.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / fmt::format("frame_source_{}_{}", name, getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A frame with structure over its whole height (a gradient and stripes), so that a
// decoder has real data to lose when the file is cut.
cv::Mat test_frame(int seed) {
  cv::Mat m(120, 160, CV_8UC1);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) m.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((x + 2 * y + 40 * seed) % 251);
  return m;
}

std::vector<std::uint8_t> encoded(const std::string& ext, int seed = 0) {
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(ext, test_frame(seed), bytes));
  return bytes;
}

void write_bytes(const fs::path& file, const std::vector<std::uint8_t>& bytes, std::size_t size) {
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(size));
}

// `count` frames dir/frame_0000.ext..., the one at `cut` (if any) cut to half its bytes.
fs::path write_sequence(const std::string& name, const std::string& ext, int count, int cut = -1) {
  const fs::path dir = fresh_dir(name);
  for (int i = 0; i < count; ++i) {
    const auto bytes = encoded(ext, i);
    write_bytes(dir / fmt::format("frame_{:04d}{}", i, ext), bytes, i == cut ? bytes.size() / 2 : bytes.size());
  }
  return dir / fmt::format("frame_%04d{}", ext);
}

std::string error_of(const std::string& source) {
  auto s = open_frame_source(source, false);
  EXPECT_FALSE(s.has_value()) << source << " opened";
  return s ? std::string() : s.error().message;
}

}  // namespace

TEST(ImageFileDamage, WholeFilesPassAndCutOnesAreNamedByFormat) {
  for (const std::string ext : {".jpg", ".png"}) {
    const auto bytes = encoded(ext);
    EXPECT_FALSE(image_file_damage(bytes).has_value()) << ext;
    // Cut anywhere (even one byte short of the end), the end marker is gone.
    for (const std::size_t keep : {bytes.size() / 4, bytes.size() / 2, bytes.size() - 1}) {
      const auto damage = image_file_damage({bytes.begin(), bytes.begin() + keep});
      ASSERT_TRUE(damage.has_value()) << ext << " cut to " << keep << " bytes";
      EXPECT_NE(damage->find(ext == ".jpg" ? "truncated JPEG" : "truncated PNG"), std::string::npos) << *damage;
    }
  }
  // Zero padding after a JPEG's end marker (some cameras write it) is not damage.
  auto padded = encoded(".jpg");
  padded.insert(padded.end(), 64, 0);
  EXPECT_FALSE(image_file_damage(padded).has_value());
  EXPECT_TRUE(image_file_damage({}).has_value());
}

// Without the check, OpenCV decodes the cut JPEG into a whole frame, its lost rows grey:
// this is what the driver must not process.
TEST(ImageFileDamage, OpenCvAloneDecodesACutJpegAsAWholeFrame) {
  const auto bytes = encoded(".jpg");
  const cv::Mat cut = cv::imdecode(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + bytes.size() / 2),
                                   cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(cut.empty());
  EXPECT_EQ(cut.size(), test_frame(0).size());
}

TEST(FrameSource, CutFilesAreDamagedAndTheFilesAroundThemStillRead) {
  for (const std::string ext : {".jpg", ".png"}) {
    const fs::path pattern = write_sequence("cut" + ext.substr(1), ext, 4, 2);
    auto source = open_frame_source(pattern.string(), false);
    ASSERT_TRUE(source.has_value()) << source.error().message;
    std::vector<std::string> kinds;
    for (int i = 0; i < 5; ++i) {
      auto r = (*source)->next();
      ASSERT_TRUE(r.has_value()) << r.error().message;
      if (r->kind == FrameRead::Kind::Frame) {
        kinds.push_back("frame " + fs::path(r->name).filename().string());
        EXPECT_EQ(r->image.size(), test_frame(0).size());
      } else if (r->kind == FrameRead::Kind::Damaged) {
        kinds.push_back("damaged " + fs::path(r->name).filename().string());
        EXPECT_NE(r->problem.find("truncated"), std::string::npos) << r->problem;
      } else {
        kinds.push_back("end");
      }
    }
    const std::vector<std::string> expected = {
        "frame frame_0000" + ext, "frame frame_0001" + ext, "damaged frame_0002" + ext,
        "frame frame_0003" + ext, "end"};
    EXPECT_EQ(kinds, expected) << ext;
  }
}

// The wrap happens inside one next(): no read comes back empty, so a paced driver
// spends exactly one period per frame, the first frame after the wrap included.
TEST(FrameSource, LoopedSequenceStartsOverWithinOneRead) {
  for (const int count : {1, 3}) {
    const fs::path pattern = write_sequence(fmt::format("loop{}", count), ".png", count);
    auto source = open_frame_source(pattern.string(), true);
    ASSERT_TRUE(source.has_value()) << source.error().message;
    for (int i = 0; i < 3 * count + 1; ++i) {
      auto r = (*source)->next();
      ASSERT_TRUE(r.has_value()) << r.error().message;
      ASSERT_EQ(r->kind, FrameRead::Kind::Frame) << "read " << i << " of a " << count << "-file loop";
      EXPECT_EQ(fs::path(r->name).filename().string(), fmt::format("frame_{:04d}.png", i % count));
    }
  }
}

TEST(FrameSource, SequenceMayStartAtOneAndAStillImageIsASequenceOfOne) {
  const fs::path dir = fresh_dir("from1");
  const auto bytes = encoded(".png");
  write_bytes(dir / "f_1.png", bytes, bytes.size());
  write_bytes(dir / "f_2.png", bytes, bytes.size());
  auto seq = open_frame_source((dir / "f_%d.png").string(), false);
  ASSERT_TRUE(seq.has_value()) << seq.error().message;
  EXPECT_EQ(fs::path((*seq)->next()->name).filename(), "f_1.png");
  EXPECT_EQ(fs::path((*seq)->next()->name).filename(), "f_2.png");
  EXPECT_EQ((*seq)->next()->kind, FrameRead::Kind::End);

  auto still = open_frame_source((dir / "f_2.png").string(), false);
  ASSERT_TRUE(still.has_value()) << still.error().message;
  EXPECT_EQ((*still)->next()->kind, FrameRead::Kind::Frame);
  EXPECT_EQ((*still)->next()->kind, FrameRead::Kind::End);
}

TEST(FrameSource, ASourceThatCannotOpenSaysWhatAndWhere) {
  const fs::path dir = fresh_dir("missing");
  const std::string no_folder = (dir / "nowhere" / "frame_%04d.png").string();
  EXPECT_EQ(error_of(no_folder), fmt::format("image sequence '{}': folder '{}' does not exist", no_folder,
                                             (dir / "nowhere").string()));
  const std::string no_file = (dir / "frame_%04d.png").string();
  EXPECT_EQ(error_of(no_file), fmt::format("image sequence '{}': neither '{}' nor '{}' exists", no_file,
                                           (dir / "frame_0000.png").string(), (dir / "frame_0001.png").string()));
  const std::string still = (dir / "still.jpg").string();
  EXPECT_EQ(error_of(still), fmt::format("image file '{}' does not exist", still));
  const std::string video = (dir / "take.avi").string();
  EXPECT_EQ(error_of(video), fmt::format("video file '{}' does not exist", video));
  const std::string bad_pattern = (dir / "frame_%s.png").string();
  EXPECT_NE(error_of(bad_pattern).find("must hold exactly one %d field"), std::string::npos);

  // For a camera, the check opens its device node only; a missing one is named. (covtrackd
  // --check does not call it for a camera: a config for hardware checks without it.)
  auto camera = check_frame_source("63");
  ASSERT_FALSE(camera.has_value());
  EXPECT_NE(camera.error().message.find("cannot open camera 63: /dev/video63: No such file or directory"),
            std::string::npos)
      << camera.error().message;
  EXPECT_TRUE(check_frame_source(write_sequence("present", ".png", 1).string()).has_value());
}

// A width too long for an int (found by mutation fuzzing: std::stoi threw, which ended
// `covtrackd --check`) is taken as 32, as every width over 32 is.
TEST(FrameSource, AFieldWidthTooLongForAnIntIsTakenAs32) {
  const fs::path dir = fresh_dir("width");
  const std::string source = (dir / "frame_%099999999999d.png").string();
  const std::string first = (dir / ("frame_" + std::string(32, '0') + ".png")).string();
  const std::string second = (dir / ("frame_" + std::string(31, '0') + "1.png")).string();
  EXPECT_EQ(error_of(source), fmt::format("image sequence '{}': neither '{}' nor '{}' exists", source, first, second));
}

// Nobody writes to these FIFOs: if a source opened one, this test would hang, not fail.
TEST(FrameSource, AFifoWhereAFileShouldBeIsRefusedWithoutOpeningIt) {
  const fs::path dir = fresh_dir("fifo");
  for (const std::string name : {"take.avi", "still.png"}) {
    const std::string fifo = (dir / name).string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_NE(error_of(fifo).find("'" + fifo + "' is a FIFO (named pipe), not a regular file"), std::string::npos)
        << error_of(fifo);
  }
  // A sequence whose second frame became a FIFO: that frame is skipped as damaged, named.
  const fs::path pattern = write_sequence("fifo_frame", ".png", 3);
  const fs::path second = pattern.parent_path() / "frame_0001.png";
  fs::remove(second);
  ASSERT_EQ(::mkfifo(second.c_str(), 0600), 0);
  auto seq = open_frame_source(pattern.string(), false);
  ASSERT_TRUE(seq.has_value()) << seq.error().message;
  EXPECT_EQ((*seq)->next()->kind, FrameRead::Kind::Frame);
  const auto fifo_frame = (*seq)->next();
  ASSERT_TRUE(fifo_frame.has_value());
  EXPECT_EQ(fifo_frame->kind, FrameRead::Kind::Damaged);
  EXPECT_EQ(fifo_frame->name, second.string());
  EXPECT_EQ(fifo_frame->problem, "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ((*seq)->next()->kind, FrameRead::Kind::Frame);
}
