// `covtrack render-tags`: AprilTags at known poses through a camera's image formation
// (lens distortion from the calibration file, blur and defocus, vignetting, shot and
// read noise, a tone curve, JPEG: tag_image_formation.hpp), written as an image sequence
// (or a video) plus a truth file. Tags are given one by one, or as the tag bundles a
// daemon config declares (a board, an object carrying tags) at a pose. The fiducial
// tracker's emulated camera: point its `source` at the output.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "commands.hpp"
#include "covtrack/emulators/fiducial/tag_image_formation.hpp"
#include "covtrack/program/command_line.hpp"
#include "fiducial_config.hpp"

namespace covtrack::cli {
namespace {

struct RenderArgs {
  std::string camera, family = "tag36h11", out, video;
  std::vector<std::string> tags, bundles;
  std::string bundles_from;
  int frames = 60;
  double swing_deg = 20, period_frames = 60;
  double wander_deg = 0, wander_m = 0;
  double noise = 3, blur = 0.8, black = 30, white = 220, background = 128;
  double gamma = 1, defocus = 0, vignetting = 0, full_well = 0;
  int jpeg = 0;
  std::string rasteriser = "supersampled";
  std::uint64_t seed = 1;
};

// The comma-separated numbers of `text` (an option's value), or nothing and an error.
std::optional<std::vector<double>> parse_numbers(const std::string& option, const std::string& text,
                                                 std::string& error) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      error = fmt::format("{} '{}': '{}' is not a number", option, text, item);
      return std::nullopt;
    }
  }
  return v;
}

// x, y, z, roll_deg, pitch_deg, yaw_deg as a pose in the camera frame, the angles applied
// as Rz(roll) Ry(yaw) Rx(pitch).
Pose camera_pose(const double* v) {
  const double k = M_PI / 180;
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(v[3] * k, Vec3::UnitZ()) * Eigen::AngleAxisd(v[5] * k, Vec3::UnitY()) *
                Eigen::AngleAxisd(v[4] * k, Vec3::UnitX())).toRotationMatrix();
  T.translation() = Vec3(v[0], v[1], v[2]);
  return T;
}

// One frame's random move, as a board waved in front of the camera: `turn` (up to
// --wander-deg about each axis) about the tag's or bundle's own centre, then `shift` (up
// to --wander-m along each camera axis). None without --wander-*.
struct Wander {
  Pose turn = Pose::Identity();
  Vec3 shift = Vec3::Zero();
  Pose apply(const Pose& T_camera_object) const {
    Pose T = T_camera_object * turn;
    T.translation() += shift;
    return T;
  }
};

Wander wander(const RenderArgs& a, std::mt19937_64& rng) {
  Wander w;
  if (a.wander_deg <= 0 && a.wander_m <= 0) return w;
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 angle = Vec3(u(rng), u(rng), u(rng)) * a.wander_deg * M_PI / 180;
  w.turn.linear() = (Eigen::AngleAxisd(angle.x(), Vec3::UnitX()) * Eigen::AngleAxisd(angle.y(), Vec3::UnitY()) *
                     Eigen::AngleAxisd(angle.z(), Vec3::UnitZ())).toRotationMatrix();
  w.shift = Vec3(u(rng), u(rng), u(rng)) * a.wander_m;
  return w;
}

// "id,size_m,x,y,z,roll_deg,pitch_deg,yaw_deg": T_camera_tag.
std::optional<fiducial::RenderedTag> parse_tag(const std::string& text, std::string& error) {
  const auto v = parse_numbers("--tag", text, error);
  if (!v) return std::nullopt;
  if (v->size() != 8 || (*v)[0] < 0 || !((*v)[1] > 0) || !((*v)[4] > 0)) {
    error = fmt::format("--tag '{}': expected id,size_m,x,y,z,roll_deg,pitch_deg,yaw_deg with "
                        "size_m > 0 and z > 0",
                        text);
    return std::nullopt;
  }
  return fiducial::RenderedTag{static_cast<int>((*v)[0]), (*v)[1], camera_pose(v->data() + 2)};
}

// A bundle of the --bundles-from config where "NAME,x,y,z,roll_deg,pitch_deg,yaw_deg" puts it
// (T_camera_bundle).
struct PlacedBundle {
  fiducial::TagBundle bundle;
  Pose T_camera_bundle;
};

std::optional<PlacedBundle> parse_bundle(const std::string& text, const std::vector<fiducial::TagBundle>& known,
                                         std::string& error) {
  const auto comma = text.find(',');
  const std::string name = text.substr(0, comma);
  const auto bundle = std::find_if(known.begin(), known.end(), [&](const auto& b) { return b.name == name; });
  if (bundle == known.end()) {
    std::vector<std::string> names;
    for (const auto& b : known) names.push_back(b.name);
    error = fmt::format("--bundle '{}': no bundle '{}' in --bundles-from (bundles there: {})", text, name,
                        names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", ")));
    return std::nullopt;
  }
  const auto v = comma == std::string::npos ? std::optional<std::vector<double>>{}
                                            : parse_numbers("--bundle", text.substr(comma + 1), error);
  if (!v || v->size() != 6 || !((*v)[2] > 0)) {
    if (error.empty())
      error = fmt::format("--bundle '{}': expected NAME,x,y,z,roll_deg,pitch_deg,yaw_deg with z > 0", text);
    return std::nullopt;
  }
  return PlacedBundle{*bundle, camera_pose(v->data())};
}

int run_render(const RenderArgs& a) {
  auto camera = load_camera(a.camera);
  if (!camera) return fmt::print(stderr, "covtrack render-tags: {}\n", camera.error().message), 2;
  auto family = fiducial::TagFamily::open(a.family);
  if (!family) return fmt::print(stderr, "covtrack render-tags: {}\n", family.error().message), 2;
  std::vector<fiducial::RenderedTag> tags;
  for (const auto& text : a.tags) {
    std::string error;
    auto t = parse_tag(text, error);
    if (!t) return fmt::print(stderr, "covtrack render-tags: {}\n", error), 2;
    tags.push_back(*t);
  }
  std::vector<PlacedBundle> bundles;
  if (!a.bundles.empty()) {
    if (a.bundles_from.empty())
      return fmt::print(stderr, "covtrack render-tags: --bundle needs --bundles-from CONFIG\n"), 2;
    auto known = fiducial::read_config_bundles(a.bundles_from);
    if (!known) return fmt::print(stderr, "covtrack render-tags: {}\n", known.error().message), 2;
    for (const auto& text : a.bundles) {
      std::string error;
      auto b = parse_bundle(text, *known, error);
      if (!b) return fmt::print(stderr, "covtrack render-tags: {}\n", error), 2;
      bundles.push_back(*b);
    }
  }
  if (tags.empty() && bundles.empty())
    return fmt::print(stderr, "covtrack render-tags: nothing to render: give --tag or --bundle\n"), 2;
  for (const auto& t : tags)
    if (!(*family)->cells(t.id))
      return fmt::print(stderr, "covtrack render-tags: {}\n", (*family)->cells(t.id).error().message), 2;
  for (const auto& b : bundles)
    for (const auto& t : b.bundle.tags)
      if (!(*family)->cells(t.id))
        return fmt::print(stderr, "covtrack render-tags: bundle {}: {}\n", b.bundle.name,
                          (*family)->cells(t.id).error().message), 2;
  std::filesystem::create_directories(a.out);
  cv::VideoWriter video;
  if (!a.video.empty()) {
    // FFV1 is lossless, so the noise in the frames is exactly the rendered noise.
    video.open(a.video, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30,
               {camera->width_px, camera->height_px}, false);
    if (!video.isOpened())
      return fmt::print(stderr, "covtrack render-tags: cannot write video '{}'\n", a.video), 1;
  }
  std::ofstream truth(std::filesystem::path(a.out) / "truth.csv");
  truth << "# frame,id,size_m,x_m,y_m,z_m,qw,qx,qy,qz  (T_camera_tag; camera: OpenCV frame)\n";
  std::ofstream bundle_truth;
  if (!bundles.empty()) {
    bundle_truth.open(std::filesystem::path(a.out) / "bundle_truth.csv");
    bundle_truth << "# frame,name,x_m,y_m,z_m,qw,qx,qy,qz  (T_camera_bundle; camera: OpenCV frame)\n";
  }
  // Levels are given in grey levels of a linear camera (gamma 1); the tone curve, if any,
  // applies on top, as a camera's does.
  fiducial::ImageFormation formation;
  formation.rasteriser = a.rasteriser == "analytic"   ? fiducial::Rasteriser::AnalyticArea
                         : a.rasteriser == "jittered" ? fiducial::Rasteriser::JitteredPoints
                                                      : fiducial::Rasteriser::Supersampled;
  formation.jitter_seed = a.seed;
  formation.ink = a.black / 255, formation.paper = a.white / 255, formation.background = a.background / 255;
  formation.gauss_blur_px = a.blur, formation.defocus_radius_px = a.defocus;
  formation.read_noise = a.noise, formation.full_well_e = a.full_well;
  formation.gamma = a.gamma, formation.vignetting = a.vignetting, formation.jpeg_quality = a.jpeg;
  formation.true_distortion = distortion_vector(*camera);  // the lens the calibration describes
  std::mt19937_64 rng(a.seed);
  for (int f = 0; f < a.frames; ++f) {
    // Each tag and each bundle swings about its own vertical axis, so the frames show motion.
    const double swing = a.swing_deg * M_PI / 180 * std::sin(2 * M_PI * f / a.period_frames);
    const Pose turn(Eigen::AngleAxisd(swing, Vec3::UnitY()).toRotationMatrix());
    const Wander moved = wander(a, rng);
    std::vector<fiducial::RenderedTag> now;
    for (const auto& t : tags) now.push_back({t.id, t.size_m, moved.apply(t.T_camera_tag * turn)});
    for (const auto& b : bundles) {
      const Pose T_camera_bundle = moved.apply(b.T_camera_bundle * turn);
      for (const auto& t : b.bundle.tags) now.push_back({t.id, t.size_m, T_camera_bundle * t.T_bundle_tag});
      const Eigen::Quaterniond q(T_camera_bundle.rotation());
      const Vec3 p = T_camera_bundle.translation();
      bundle_truth << fmt::format("{},{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f}\n", f, b.bundle.name, p.x(),
                                  p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
    }
    for (const auto& t : now) {
      const Eigen::Quaterniond q(t.T_camera_tag.rotation());
      const Vec3 p = t.T_camera_tag.translation();
      truth << fmt::format("{},{},{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f}\n", f, t.id,
                           t.size_m, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
    }
    const cv::Mat image = fiducial::form_image(*camera, **family, now, formation, rng);
    if (video.isOpened()) video.write(image);
    else cv::imwrite((std::filesystem::path(a.out) / fmt::format("frame_{:04d}.png", f)).string(), image);
  }
  fmt::print("covtrack render-tags: {} frames -> {}{}\n", a.frames,
             a.video.empty() ? a.out + "/frame_%04d.png" : a.video, ", truth in " + a.out + "/truth.csv");
  return 0;
}

}  // namespace

void add_render_tags_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render-tags", "render AprilTags at known poses (images or "
                                                    "video + truth.csv): the fiducial emulator");
  cmd->add_option("--camera", args->camera, "camera calibration: OpenCV (YAML/XML) or ROS camera_info YAML")->required();
  cmd->add_option("--out,-o", args->out, "output folder (frames and truth.csv)")->required();
  cmd->add_option("--tag", args->tags, "id,size_m,x,y,z,roll_deg,pitch_deg,yaw_deg (T_camera_tag; "
                                       "repeat for more tags)");
  cmd->add_option("--bundle", args->bundles, "NAME,x,y,z,roll_deg,pitch_deg,yaw_deg: every tag of the "
                                             "bundle NAME of --bundles-from, at T_camera_bundle (repeat for "
                                             "more); its truth goes to bundle_truth.csv");
  cmd->add_option("--bundles-from", args->bundles_from, "a covtrackd config whose fiducial devices declare "
                                                        "the bundles (their [[bundles]])");
  cmd->add_option("--family", args->family, "AprilTag family")->capture_default_str();
  cmd->add_option("--video", args->video, "write this video file (FFV1) instead of PNG frames");
  cmd->add_option("--frames,-n", args->frames, "frame count")->capture_default_str()->check(program::in_range(1, 1000000));
  cmd->add_option("--swing-deg", args->swing_deg, "yaw swing amplitude")->capture_default_str();
  cmd->add_option("--period-frames", args->period_frames, "frames per swing")->capture_default_str()->check(program::positive());
  cmd->add_option("--wander-deg", args->wander_deg, "each frame, turn every tag and bundle about its centre by "
                                                   "a random angle up to this about each axis (a board waved in "
                                                   "front of the camera)")
      ->capture_default_str()->check(program::in_range(0.0, 90.0));
  cmd->add_option("--wander-m", args->wander_m, "each frame, move every tag and bundle by up to this along "
                                               "each camera axis")
      ->capture_default_str()->check(program::in_range(0.0, 10.0));
  cmd->add_option("--noise", args->noise, "sensor noise sigma (grey levels)")->capture_default_str()->check(program::in_range(0.0, 100.0));
  cmd->add_option("--blur", args->blur, "optical blur sigma (px)")->capture_default_str()->check(program::in_range(0.0, 20.0));
  cmd->add_option("--black", args->black, "tag black level")->capture_default_str();
  cmd->add_option("--white", args->white, "tag white level")->capture_default_str();
  cmd->add_option("--background", args->background, "background level")->capture_default_str();
  cmd->add_option("--seed", args->seed, "noise seed")->capture_default_str();
  cmd->add_option("--gamma", args->gamma, "the camera's tone curve: grey = 255 (linear)^(1/gamma); "
                                          "sRGB-like cameras are near 2.2")
      ->capture_default_str()->check(program::in_range(0.2, 5.0));
  cmd->add_option("--defocus", args->defocus, "defocus disk radius (px), on top of --blur")
      ->capture_default_str()->check(program::in_range(0.0, 20.0));
  cmd->add_option("--vignetting", args->vignetting, "light lost at the frame's corners (0-0.9)")
      ->capture_default_str()->check(program::in_range(0.0, 0.9));
  cmd->add_option("--full-well", args->full_well, "electrons at full scale, for shot noise (0: none)")
      ->capture_default_str()->check(program::in_range(0.0, 1e7));
  cmd->add_option("--jpeg", args->jpeg, "JPEG quality the camera compresses with (0: none)")
      ->capture_default_str()->check(program::in_range(0, 100));
  cmd->add_option("--rasteriser", args->rasteriser, "how tags are drawn: supersampled (texture "
                                                    "warped 4x finer, area-averaged), analytic "
                                                    "(exact covered area per pixel) or jittered "
                                                    "(256 random points per pixel)")
      ->capture_default_str()->check(CLI::IsMember({"supersampled", "analytic", "jittered"}));
  cmd->callback([args] {
    const int rc = run_render(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace covtrack::cli
