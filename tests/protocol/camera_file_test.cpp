// Calibration files: OpenCV's YAML and XML and ROS's camera_info YAML read into the
// camera model, and every kind of damaged file an error naming the file (and the key),
// never a hang, a crash or a huge allocation.
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "client/example_camera.hpp"
#include "covtrack/protocol/camera.hpp"

using namespace covtrack;

namespace {
std::filesystem::path write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}
const char* kMatrix =
    "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
    "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n";
const char* kDist =
    "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
    "   data: [ 0.1, -0.2, 0., 0., 0.05 ]\n";
}  // namespace

TEST(CameraFile, LoadsTheShippedExample) {
  const auto cam = load_camera(COVTRACK_SOURCE_DIR "/config/cameras/example_640x480.yml");
  ASSERT_TRUE(cam) << cam.error().message;
  const auto ref = test::example_camera();
  EXPECT_EQ(cam->width_px, 640);
  EXPECT_EQ(cam->height_px, 480);
  EXPECT_DOUBLE_EQ(cam->fx, ref.fx);
  EXPECT_DOUBLE_EQ(cam->cy, ref.cy);
  EXPECT_DOUBLE_EQ(cam->k3, ref.k3);
  EXPECT_DOUBLE_EQ(cam->p1, ref.p1);
  EXPECT_DOUBLE_EQ(cam->intrinsic_sigmas_px[0], 1.8);
}

TEST(CameraFile, MissingFileNamesTheFile) {
  const auto cam = load_camera("/nonexistent/cam.yml");
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("/nonexistent/cam.yml"), std::string::npos);
}

TEST(CameraFile, MissingKeyNamesFileAndKey) {
  const auto path = write_temp("covtrack_cam_nokey.yml",
                               std::string("%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n") + kDist);
  const auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find(path.string()), std::string::npos) << cam.error().message;
  EXPECT_NE(cam.error().message.find("camera_matrix"), std::string::npos) << cam.error().message;
}

TEST(CameraFile, MissingImageSizeAndUnsupportedDistortion) {
  auto path = write_temp("covtrack_cam_nosize.yml",
                         std::string("%YAML:1.0\n---\nimage_width: 640\n") + kMatrix + kDist);
  auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("image_height"), std::string::npos) << cam.error().message;

  path = write_temp("covtrack_cam_rational.yml",
                    std::string("%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n") + kMatrix +
                        "distortion_coefficients: !!opencv-matrix\n   rows: 8\n   cols: 1\n"
                        "   dt: d\n   data: [ 0.1, -0.2, 0., 0., 0.05, 0.3, 0., 0. ]\n");
  cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("distortion_coefficients"), std::string::npos);
}

// A coefficient no lens has: the fuzzer's k3 = -3e301 made the intrinsic covariance infinite.
TEST(CameraFile, AnAbsurdDistortionCoefficientIsNamed) {
  const auto path = write_temp("covtrack_cam_absurd_k3.yml",
                               std::string("%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n") + kMatrix +
                                   "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n"
                                   "   dt: d\n   data: [ 0.1, -0.2, 0., 0., -2.915e301 ]\n");
  const auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("coefficient 4 is -2.915e+301, beyond any lens"), std::string::npos)
      << cam.error().message;
}

TEST(CameraFile, AnImpossibleImageSizeIsAnErrorNotAnAllocation) {
  const auto path = write_temp("covtrack_cam_huge.yml", std::string("%YAML:1.0\n---\nimage_width: 2000000000\n"
                                                                    "image_height: 480\n") + kMatrix + kDist);
  const auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("image_width"), std::string::npos) << cam.error().message;
  EXPECT_NE(cam.error().message.find("2000000000"), std::string::npos) << cam.error().message;
}

// The intrinsics' standard deviations become a covariance of every pixel: one that is not
// finite, or negative, is named, not carried into the regions.
TEST(CameraFile, IntrinsicSigmasMustBeFiniteAndNotNegative) {
  const std::string head = std::string("%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n") + kMatrix + kDist;
  const auto with_sigmas = [&](const std::string& name, const std::string& data) {
    return write_temp(name, head + "intrinsics_std_deviations: !!opencv-matrix\n   rows: 4\n   cols: 1\n"
                                   "   dt: d\n   data: [ " + data + " ]\n");
  };
  const auto fine = load_camera(with_sigmas("covtrack_cam_sigmas.yml", "1.5, 1.5, 0., 2."));
  ASSERT_TRUE(fine) << fine.error().message;
  EXPECT_DOUBLE_EQ(fine->intrinsic_sigmas_px[3], 2.0);
  for (const auto& [name, data, what] : {std::tuple{"covtrack_cam_nan_sigma.yml", ".Nan, 1.5, 1., 1.", "fx is"},
                                         {"covtrack_cam_inf_sigma.yml", "1.5, .Inf, 1., 1.", "fy is inf"},
                                         {"covtrack_cam_negative_sigma.yml", "1.5, 1.5, -1., 1.", "cx is -1"}}) {
    const auto path = with_sigmas(name, data);
    const auto cam = load_camera(path);
    ASSERT_FALSE(cam) << data;
    EXPECT_NE(cam.error().message.find(path.string()), std::string::npos) << cam.error().message;
    EXPECT_NE(cam.error().message.find(std::string("intrinsics_std_deviations': ") + what), std::string::npos)
        << cam.error().message;
  }
}

// A matrix's size is checked before its data is (OpenCV, which once read these files,
// allocated rows x cols first: a fuzzer's "rows:`3" asked for 48 GB).
TEST(CameraFile, AMatrixSizeBeyondACalibrationsIsAnError) {
  for (const std::string rows : {"3.5", "x", "3000000", "-3", "0", "99999999999999999999"}) {
    const auto path = write_temp("covtrack_cam_rows.yml",
                                 "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                                 "camera_matrix: !!opencv-matrix\n   rows: " + rows + "\n   cols: 3\n   dt: d\n"
                                 "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n" + kDist);
    const auto cam = load_camera(path);
    ASSERT_FALSE(cam) << rows;
    EXPECT_NE(cam.error().message.find("camera_matrix': rows and cols"), std::string::npos) << cam.error().message;
  }
}

// A binary file, and text nested deeper than any calibration, are refused before a
// reader sees them (calibration_text.hpp), by name and byte.
TEST(CameraFile, BinaryOrDeeplyNestedTextIsRefusedFirst) {
  const auto byte_ff = write_temp("covtrack_cam_ff.yml", " -\xff\n-\n-");
  auto cam = load_camera(byte_ff);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("byte 2 is 0xFF"), std::string::npos) << cam.error().message;
  const auto deep = write_temp("covtrack_cam_deep.yml", "%YAML:1.0\n---\na: " + std::string(100000, '[') + "\n");
  cam = load_camera(deep);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("nested more than 32 deep"), std::string::npos) << cam.error().message;
  const auto deep_xml = write_temp("covtrack_cam_deep.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>" +
                                                                 std::string(100000, '<') + "</opencv_storage>\n");
  cam = load_camera(deep_xml);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("nested more than 32 deep"), std::string::npos) << cam.error().message;
}

TEST(CameraFile, GarbageIsAnErrorNotACrash) {
  const auto path = write_temp("covtrack_cam_garbage.yml", "%YAML:1.0\n---\n[[[ :: not yaml\n");
  const auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find(path.string()), std::string::npos);
}

// OpenCV throws when a key is looked up in a top level that is not a map (a list, a
// scalar): found by fuzz_camera, where it ended the process.
TEST(CameraFile, ATopLevelThatIsNotAMapIsAnErrorNotACrash) {
  for (const auto& [name, text] : {std::pair{"covtrack_cam_list.yml", "%YAML:1.0\n---\n- 1\n- 2\n"},
                                   {"covtrack_cam_ros_list.yaml", "- image_width\n- 640\n"},
                                   {"covtrack_cam_scalar.yml", "%YAML:1.0\n---\n640\n"}}) {
    const auto path = write_temp(name, text);
    const auto cam = load_camera(path);
    ASSERT_FALSE(cam) << text;
    EXPECT_NE(cam.error().message.find(path.string()), std::string::npos) << cam.error().message;
  }
}

// ROS's camera_info YAML (what `rosrun camera_calibration` saves): the same camera as
// the shipped OpenCV file, and its other lens models refused by name.
TEST(CameraFile, ReadsRosCameraInfoYaml) {
  const auto ros = load_camera(COVTRACK_SOURCE_DIR "/tests/data/ros_camera_info_640x480.yaml");
  ASSERT_TRUE(ros) << ros.error().message;
  const auto cv = load_camera(COVTRACK_SOURCE_DIR "/config/cameras/example_640x480.yml");
  ASSERT_TRUE(cv) << cv.error().message;
  EXPECT_EQ(ros->width_px, 640);
  EXPECT_EQ(ros->height_px, 480);
  for (const auto& [a, b] : {std::pair{ros->fx, cv->fx}, {ros->fy, cv->fy}, {ros->cx, cv->cx}, {ros->cy, cv->cy},
                             {ros->k1, cv->k1}, {ros->k2, cv->k2}, {ros->p1, cv->p1}, {ros->p2, cv->p2},
                             {ros->k3, cv->k3}})
    EXPECT_NEAR(a, b, 1e-9 * (1 + std::abs(b)));
  const Vec3 p(0.2, -0.1, 1.0);
  EXPECT_LT((ros->project(p) - cv->project(p)).norm(), 1e-9);
}

TEST(CameraFile, RosCameraInfoMistakesAreNamed) {
  const std::string head = "image_width: 640\nimage_height: 480\n"
                           "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n";
  auto path = write_temp("covtrack_ros_fisheye.yaml", head + "distortion_model: equidistant\n"
                                                             "distortion_coefficients:\n  rows: 1\n  cols: 4\n"
                                                             "  data: [0.1, 0.01, 0, 0]\n");
  auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("distortion_model 'equidistant'"), std::string::npos) << cam.error().message;
  EXPECT_NE(cam.error().message.find(path.string()), std::string::npos) << cam.error().message;

  path = write_temp("covtrack_ros_short.yaml", head + "distortion_model: plumb_bob\n"
                                                      "distortion_coefficients:\n  rows: 1\n  cols: 5\n"
                                                      "  data: [0.1, 0.01, 0]\n");
  cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("1 x 5 matrix with 3 data entries"), std::string::npos) << cam.error().message;

  // An undistorted camera: ROS writes an empty list.
  path = write_temp("covtrack_ros_pinhole.yaml", head + "distortion_model: plumb_bob\n"
                                                        "distortion_coefficients:\n  rows: 1\n  cols: 0\n"
                                                        "  data: []\n");
  cam = load_camera(path);
  ASSERT_TRUE(cam) << cam.error().message;
  EXPECT_EQ(cam->k1, 0);
  EXPECT_DOUBLE_EQ(cam->fx, 500);
}

// Damaged text on which OpenCV 4.6's reader looped forever (found by fuzz_camera), block
// nesting, which the text check does not count, and XML cut short: each an error naming
// the file, at once.
TEST(CameraFile, TextOpenCVHungOnIsAnError) {
  for (const auto& [name, text] :
       {std::pair{"covtrack_cam_dashes.yml", std::string("%YAML:1.0\n---\n  a: 1\n--\n-0")},
        {"covtrack_cam_block_nesting.yml", "%YAML:1.0\n---\na:\n" + [] {
           std::string s;
           for (int i = 0; i < 20000; ++i) s += "- ";
           return s;
         }() + "1\n"},
        {"covtrack_cam_unclosed.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640\n"}}) {
    const auto path = write_temp(name, text);
    const auto cam = load_camera(path);
    ASSERT_FALSE(cam) << name;
    EXPECT_EQ(cam.error().message.rfind(path.string() + ": ", 0), 0u) << cam.error().message;
    if (std::string(name).find("nesting") != std::string::npos) {
      EXPECT_NE(cam.error().message.find("nested more than"), std::string::npos) << cam.error().message;
    }
  }
}

// A key given twice is a damaged or hand-merged file: which value was meant is unknown.
TEST(CameraFile, AKeyGivenTwiceIsAnError) {
  auto path = write_temp("covtrack_cam_twice.yml", std::string("%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                                                               "image_width: 800\n") + kMatrix + kDist);
  auto cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("key 'image_width' is given twice (line 5"), std::string::npos)
      << cam.error().message;
  path = write_temp("covtrack_cam_twice.xml", "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
                                              "<image_width>800</image_width>\n</opencv_storage>\n");
  cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("key 'image_width' is given twice (line 4)"), std::string::npos)
      << cam.error().message;
}

// What OpenCV itself writes, in YAML, XML and JSON (cv::FileStorage, as its calibration
// sample and save_camera do), reads back as the camera written.
TEST(CameraFile, ReadsWhatOpenCVWritesInYamlXmlAndJson) {
  auto written = test::example_camera();
  written.intrinsic_sigmas_px = {1.8, 1.7, 0.9, 1.1};
  for (const char* name : {"covtrack_cam_written.yml", "covtrack_cam_written.xml", "covtrack_cam_written.json"}) {
    const auto path = std::filesystem::temp_directory_path() / name;
    ASSERT_TRUE(save_camera(written, path).has_value()) << name;
    const auto cam = load_camera(path);
    ASSERT_TRUE(cam) << cam.error().message;
    EXPECT_EQ(cam->width_px, written.width_px);
    EXPECT_EQ(cam->height_px, written.height_px);
    for (const auto& [a, b] : {std::pair{cam->fx, written.fx}, {cam->fy, written.fy}, {cam->cx, written.cx},
                               {cam->cy, written.cy}, {cam->k1, written.k1}, {cam->k2, written.k2},
                               {cam->p1, written.p1}, {cam->p2, written.p2}, {cam->k3, written.k3}})
      EXPECT_DOUBLE_EQ(a, b) << name;
    EXPECT_EQ(cam->intrinsic_sigmas_px, written.intrinsic_sigmas_px) << name;
  }
  // The same by content when the name says neither: OpenCV's FORMAT_AUTO, by the first character.
  const auto xml = std::filesystem::temp_directory_path() / "covtrack_cam_written.xml";
  const auto unnamed = std::filesystem::temp_directory_path() / "covtrack_cam_written.calib";
  std::filesystem::copy_file(xml, unnamed, std::filesystem::copy_options::overwrite_existing);
  const auto cam = load_camera(unnamed);
  ASSERT_TRUE(cam) << cam.error().message;
  EXPECT_DOUBLE_EQ(cam->fx, written.fx);
}

// OpenCV's matrix element types, one value per entry or a channel count ("2d"), and a
// matrix in single precision ("f") read as written.
TEST(CameraFile, OpenCVElementTypes) {
  const std::string head = "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n";
  const auto with_dist_dt = [&](const std::string& name, const std::string& dims) {
    return write_temp(name, head + kMatrix + "distortion_coefficients: !!opencv-matrix\n" + dims +
                                "   data: [ 0.1, -0.2, 0., 0. ]\n");
  };
  auto cam = load_camera(with_dist_dt("covtrack_cam_dt_f.yml", "   rows: 4\n   cols: 1\n   dt: f\n"));
  ASSERT_TRUE(cam) << cam.error().message;
  EXPECT_DOUBLE_EQ(cam->k2, -0.2);
  cam = load_camera(with_dist_dt("covtrack_cam_dt_2d.yml", "   rows: 2\n   cols: 1\n   dt: 2d\n"));
  ASSERT_TRUE(cam) << cam.error().message;
  EXPECT_DOUBLE_EQ(cam->p1, 0.0);
  const auto path = with_dist_dt("covtrack_cam_dt_bad.yml", "   rows: 4\n   cols: 1\n   dt: q\n");
  cam = load_camera(path);
  ASSERT_FALSE(cam);
  EXPECT_NE(cam.error().message.find("distortion_coefficients': dt 'q' is not an OpenCV element type"), std::string::npos)
      << cam.error().message;
}
