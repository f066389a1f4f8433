#include "fiducial_config.hpp"

#include <deque>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "covtrack/devices/device_keys.hpp"
#include "covtrack/devices/pose_keys.hpp"
#include "covtrack/protocol/camera.hpp"
#include "covtrack/protocol/channels.hpp"
#include "frame_source.hpp"

namespace covtrack::fiducial {

const TableSpec& fiducial_device_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name> (type = \"fiducial\")", "fiducial driver", device_common_keys()};
    const std::vector<KeySpec> own = {
        {"source", ValueType::String, "", "", "camera: V4L2 index (\"0\"); or image files: a "
         "pattern (\"frames/frame_%04d.png\", numbered from 0 or 1) or one image; or a video file; "
         "relative to this file; `covtrackd --check` opens files, not a camera (it may be plugged in later)"},
        {"calibration", ValueType::String, "", "", "camera calibration: OpenCV's file (camera_matrix, "
         "distortion_coefficients, image_width, image_height) or ROS's camera_info YAML; relative to this file; "
         "`covtrackd --check` reads it"},
        {"family", ValueType::String, "", "\"tag36h11\"", "AprilTag family"},
        {"decimate", ValueType::Float, "", "2", "quad search on an image this much smaller", 1, 8},
        {"quad_sigma", ValueType::Float, "px", "0", "blur before the quad search (0.8 speeds up "
         "noisy frames)", 0, 10},
        {"threads", ValueType::Integer, "", "1", "detector threads", 1, 64},
        {"corner_calibration", ValueType::String, "", "none", "this camera's corner noise model: a file "
         "written by `covtrack calibrate-fiducial` (the corner_* keys in its [corner_model] table); "
         "relative to this file; corner_* keys may not be given here as well"},
        {"ambiguity_chi2", ValueType::Float, "", "40", "inflate the covariance to cover the second "
         "pose when it fits within this many corner variances", 0, 1e6},
        {"rate_hz", ValueType::Float, "Hz", "30", "files: frames per second (0: as fast as "
         "possible); cameras run at their own rate", 0, 10000},
        {"loop", ValueType::Boolean, "", "true", "files: start over at the end"},
        {"publish_raw", ValueType::Boolean, "", "true", "publish detections on covtrack/raw/<name> "
         "(format: devices/fiducial/README.md)"},
        {"publish_images", ValueType::Boolean, "", "false", "publish the frames detected on, as JPEG, on "
         "covtrack/image/<name> with their poses' measurement time (a recorded session then shows "
         "the camera's picture in `covtrack view --log`)"},
        {"image_every_n", ValueType::Integer, "", "1", "publish_images: one image per this many "
         "frames", 1, 10000},
        {"image_jpeg_quality", ValueType::Integer, "", "80", "publish_images: JPEG quality (higher: "
         "larger, sharper)", 1, 100},
        {"tags", ValueType::TableArray, "", "[]", "the tag map: [[devices.<name>.tags]], each tag a "
         "sensor of its own; tags neither here nor in a bundle are ignored"},
        {"bundles", ValueType::TableArray, "", "[]", "tag bundles: [[devices.<name>.bundles]], each a "
         "rigid set of tags posed as one sensor from all their corners (devices/fiducial/README.md)"},
        {"bundle_consistency_chi2", ValueType::Float, "", "40", "a bundle's tag whose own pose is further "
         "than this chi-square (6 dof) from where its other tags put it disagrees: it is left out (or, "
         "without a majority, covered) and the bundle is DEGRADED", 0, 1e12},
    };
    s.keys.insert(s.keys.end(), own.begin(), own.end());
    const auto corner = corner_model_keys();
    s.keys.insert(s.keys.end(), corner.begin(), corner.end());
    return s;
  }();
  return spec;
}

std::vector<KeySpec> corner_model_keys() {
  std::vector<KeySpec> keys{
        {"corner_gain_px", ValueType::Float, "px", "", "corner noise model: noise/contrast gain "
         "(devices/fiducial/README.md)", 0, 100},
        {"corner_floor_px", ValueType::Float, "px", "", "corner noise model: per-camera floor "
         "for any tag size", 0, 100},
        {"corner_sample_floor_px", ValueType::Float, "px", "", "corner noise model: per-camera "
         "floor of each edge sample, averaged by the edge fit (shrinks as 128 / edge length above "
         "128 px; like the gain's term, it turns edges three times as much as it moves them)", 0, 100},
        {"corner_aligned_px", ValueType::Float, "px", "", "corner noise model: edges along "
         "pixel axes", 0, 100},
        {"corner_shift_px", ValueType::Float, "px", "", "corner noise model: outward shift of "
         "an edge lined inside by white cells, at zero border width (corrected)", 0, 100},
        {"corner_shift_falloff", ValueType::Float, "", "", "corner noise model: that shift "
         "fades as exp(-falloff (border / blur)^2)", 0, 100},
        {"corner_shift_sigma_px", ValueType::Float, "px", "", "corner noise model: what the "
         "shift correction misses, at full reach", 0, 100},
        {"corner_scale_bias_per_blur", ValueType::Float, "", "", "corner noise model: every "
         "edge's mean outward error per px of edge blur for a dark square (a light one: the "
         "opposite), from the camera's tone curve (removed)", -10, 10},
        {"corner_scale_sigma_px", ValueType::Float, "px", "", "corner noise model: spread of "
         "the four edges' common outward error (the tag's apparent size), floor", 0, 100},
        {"corner_scale_per_blur", ValueType::Float, "", "", "corner noise model: that spread's "
         "growth per px of edge blur", 0, 100},
        {"corner_edge_sigma_px", ValueType::Float, "px", "", "corner noise model: spread of each "
         "edge's own outward error, floor, for a 64 px edge (both terms scale as 64 / length)", 0, 100},
        {"corner_edge_per_blur", ValueType::Float, "", "", "corner noise model: that spread's "
         "growth per px of edge blur", 0, 100},
        {"corner_tilt_sigma_px", ValueType::Float, "px", "", "corner noise model: spread of "
         "each edge's own turn (its ends' opposite outward errors), floor, for a 64 px edge (both "
         "terms scale as 64 / length)", 0, 100},
        {"corner_tilt_per_blur", ValueType::Float, "", "", "corner noise model: that spread's "
         "growth per px of edge blur", 0, 100},
        {"corner_locked_edge_px", ValueType::Float, "px", "", "corner noise model: spread of the "
         "outward error of an edge that stays at one sub-pixel phase along its length (along a "
         "pixel row or column)", 0, 100},
        {"corner_locked_tilt_px", ValueType::Float, "px", "", "corner noise model: spread of "
         "such an edge's turn (which stays locked over up to ~2 px of drift across the grid)", 0, 100},
  };
  // The defaults are CornerNoiseModel's own (corner_noise.hpp): written in one place.
  static const auto default_text = [] {
    std::map<std::string_view, std::string> text;
    const CornerNoiseModel defaults;
    for (const CornerModelField& f : corner_model_fields()) text[f.key] = fmt::format("{:.6g}", defaults.*f.value);
    return text;
  }();
  for (KeySpec& k : keys) k.default_value = default_text.at(k.key);
  return keys;
}

const std::vector<CornerModelField>& corner_model_fields() {
  using M = CornerNoiseModel;
  static const std::vector<CornerModelField> fields{
      {"corner_gain_px", &M::gain_px}, {"corner_floor_px", &M::floor_px},
      {"corner_sample_floor_px", &M::sample_floor_px}, {"corner_aligned_px", &M::aligned_px},
      {"corner_shift_px", &M::shift_px}, {"corner_shift_falloff", &M::shift_falloff},
      {"corner_shift_sigma_px", &M::shift_sigma_px}, {"corner_scale_bias_per_blur", &M::scale_bias_per_blur},
      {"corner_scale_sigma_px", &M::scale_sigma_px}, {"corner_scale_per_blur", &M::scale_per_blur},
      {"corner_edge_sigma_px", &M::edge_sigma_px}, {"corner_edge_per_blur", &M::edge_per_blur},
      {"corner_tilt_sigma_px", &M::tilt_sigma_px}, {"corner_tilt_per_blur", &M::tilt_per_blur},
      {"corner_locked_edge_px", &M::locked_edge_px}, {"corner_locked_tilt_px", &M::locked_tilt_px}};
  return fields;
}

const TableSpec& corner_calibration_spec() {
  static const TableSpec spec{"corner_model (a corner_calibration file)", "fiducial driver", corner_model_keys()};
  return spec;
}

const TableSpec& fiducial_tag_spec() {
  static const TableSpec spec{
      "devices.<name>.tags (type = \"fiducial\")",
      "fiducial driver",
      {
          {"id", ValueType::Integer, "", "", "tag id in the family; its sensor is \"tag<id>\"", 0, 1e6},
          {"size_m", ValueType::Float, "m", "", "edge of the detected square (black border's outer "
           "edge)", 1e-4, 100},
      }};
  return spec;
}

const TableSpec& fiducial_bundle_spec() {
  static const TableSpec spec{
      "devices.<name>.bundles[] (type = \"fiducial\")",
      "fiducial driver",
      {
          {"name", ValueType::String, "", "", "the bundle's sensor name (1-23 of A-Z a-z 0-9 _ -); its pose "
           "is T_camera_bundle"},
          {"publish_tags", ValueType::Boolean, "", "false", "also publish each of its tags on its own, as "
           "tag<id>"},
          {"tags", ValueType::TableArray, "", "", "its tags: [[devices.<name>.bundles.tags]]"},
      }};
  return spec;
}

const TableSpec& fiducial_bundle_tag_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name>.bundles[].tags[] (type = \"fiducial\"; the pose is T_bundle_tag: parent the "
                "bundle, child the tag)",
                "fiducial driver",
                {
                    {"id", ValueType::Integer, "", "", "tag id in the family; a tag belongs to one bundle at "
                     "most, and then not to the tag map", 0, 1e6},
                    {"size_m", ValueType::Float, "m", "", "edge of the detected square", 1e-4, 100},
                }};
    const auto pose = pose_keys();
    s.keys.insert(s.keys.end(), pose.begin(), pose.end());
    return s;
  }();
  return spec;
}

namespace {
std::string relative_to_config(const std::string& path, const std::string& config_file) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(config_file).parent_path() / path).string();
}

// The corner_* keys of `r`, each defaulting to `m`'s value.
CornerNoiseModel read_corner_model_keys(TableReader& r, CornerNoiseModel m) {
  for (const CornerModelField& f : corner_model_fields()) m.*f.value = r.number(f.key, m.*f.value);
  if (m.floor_px <= 0 && m.sample_floor_px <= 0 && m.gain_px <= 0)
    r.error("corner_floor_px", "the corner noise model needs a floor, a sample floor or a gain above zero");
  return m;
}

// Who claims a tag id: the tag map, or a bundle (by its name, which cannot be this).
constexpr const char* kTagMap = "[[tags]]";

// One [[bundles]] entry. `owner` maps every tag id already claimed to its claimant, so
// that a tag is claimed once.
TagBundle read_bundle(TableReader& r, std::map<int, std::string>& owner) {
  TagBundle b;
  b.name = r.string("name");
  if (r.has("name") && !is_valid_name(b.name))
    r.error("name", fmt::format("'{}' is not a sensor name (1-23 of A-Z a-z 0-9 _ -)", b.name));
  b.publish_tags = r.boolean("publish_tags", false);
  const auto tables = r.tables("tags");
  if (r.has("tags") && tables.empty()) r.error("tags", "a bundle needs at least one tag");
  for (std::size_t i = 0; i < tables.size(); ++i) {
    TableReader tr(*tables[i], r.path(fmt::format("tags[{}]", i)), fiducial_bundle_tag_spec(), r.file(), r.errors());
    BundleTag t;
    t.id = static_cast<int>(tr.integer("id", 0));
    t.size_m = tr.number("size_m", 0.1);
    t.T_bundle_tag = read_pose(tr);
    if (const auto claimed = owner.find(t.id); tr.has("id") && claimed != owner.end())
      tr.error("id", claimed->second == kTagMap
                         ? fmt::format("tag {} is in the tag map ([[tags]]) too: list it once (publish_tags = "
                                       "true publishes a bundle's tags on their own)", t.id)
                     : claimed->second == b.name
                         ? fmt::format("tag {} is listed twice in bundle '{}'", t.id, b.name)
                         : fmt::format("tag {} is in bundle '{}' already: a tag belongs to one bundle at most",
                                       t.id, claimed->second));
    else
      owner[t.id] = b.name;
    b.tags.push_back(t);
  }
  return b;
}
}  // namespace

std::shared_ptr<const FiducialConfig> read_fiducial_config(TableReader& r, const std::string& device_name) {
  FiducialConfig c;
  c.device = device_name;
  c.parent_frame = r.string("parent_frame", "world");
  c.source = r.string("source");
  // --check opens the files a config names, not devices: a config written for a camera
  // checks on a machine without it (as a serial port or HID device is not opened either).
  if (!is_camera_index(c.source)) {
    c.source = relative_to_config(c.source, r.file());
    r.resource("source", [source = c.source] { return check_frame_source(source); });
  }
  c.calibration = relative_to_config(r.string("calibration"), r.file());
  r.resource("calibration", [file = c.calibration]() -> Result<void> {
    if (auto camera = load_camera(file); !camera) return std::unexpected(camera.error());
    return {};
  });
  c.detector.family = r.string("family", "tag36h11");
  bool known = false;
  for (const auto& f : tag_family_names()) known |= f == c.detector.family;
  if (!known)
    r.error("family", fmt::format("unknown AprilTag family '{}' (known: {})", c.detector.family,
                                  fmt::join(tag_family_names(), ", ")));
  c.detector.decimate = r.number("decimate", 2);
  c.detector.quad_sigma = r.number("quad_sigma", 0);
  c.detector.threads = static_cast<int>(r.integer("threads", 1));
  c.noise = read_corner_model_keys(r, c.noise);
  c.corner_calibration = relative_to_config(r.string("corner_calibration"), r.file());
  if (!c.corner_calibration.empty()) {
    for (const KeySpec& k : corner_model_keys())
      if (r.has(k.key))
        r.error(k.key, fmt::format("is given here and by corner_calibration '{}': give the corner model once",
                                    c.corner_calibration));
    if (auto model = read_corner_calibration(c.corner_calibration)) c.noise = *model;
    else r.error("corner_calibration", model.error().message);
  }
  c.ambiguity_chi2 = r.number("ambiguity_chi2", c.ambiguity_chi2);
  c.rate_hz = r.number("rate_hz", 30);
  c.loop = r.boolean("loop", true);
  c.publish_raw = r.boolean("publish_raw", true);
  c.publish_images = r.boolean("publish_images", false);
  c.image_every_n = static_cast<int>(r.integer("image_every_n", 1));
  c.image_jpeg_quality = static_cast<int>(r.integer("image_jpeg_quality", 80));
  for (const toml::table* t : r.tables("tags")) {
    TableReader tr(*t, r.path("tags"), fiducial_tag_spec(), r.file(), r.errors());
    const int id = static_cast<int>(tr.integer("id", 0));
    const double size = tr.number("size_m", 0.1);
    if (c.tag_size_m.count(id)) tr.error("id", fmt::format("tag {} is listed twice", id));
    c.tag_size_m[id] = size;
  }
  c.bundle_consistency_chi2 = r.number("bundle_consistency_chi2", c.bundle_consistency_chi2);
  std::map<int, std::string> owner;  // who claims each tag id
  for (const auto& [id, size] : c.tag_size_m) owner[id] = kTagMap;
  std::deque<TableReader> bundle_readers;  // kept for the checks that need every bundle read
  std::set<std::string> bundle_names;  // one error per repeated name, not one per pair
  for (const toml::table* t : r.tables("bundles")) {
    TableReader& br = bundle_readers.emplace_back(
        *t, r.path(fmt::format("bundles[{}]", bundle_readers.size())), fiducial_bundle_spec(), r.file(), r.errors());
    TagBundle b = read_bundle(br, owner);
    if (!bundle_names.insert(b.name).second) br.error("name", fmt::format("bundle '{}' is named twice", b.name));
    c.bundles.push_back(b);
  }
  // A bundle named like a tag's sensor would share its stream.
  std::map<std::string, int> tag_sensors;
  for (const auto& [id, claimant] : owner) tag_sensors[fmt::format("tag{}", id)] = id;
  for (std::size_t i = 0; i < c.bundles.size(); ++i)
    if (const auto tag = tag_sensors.find(c.bundles[i].name); tag != tag_sensors.end())
      bundle_readers[i].error("name", fmt::format("'{}' is the sensor name of tag {}", tag->first, tag->second));
  if (c.tag_size_m.empty() && c.bundles.empty())
    r.error("tags", "needs at least one [[tags]] entry (id, size_m) or [[bundles]] entry");
  return std::make_shared<const FiducialConfig>(std::move(c));
}

Result<CornerNoiseModel> read_corner_calibration(const std::string& file) {
  auto text = read_config_text(file);
  if (!text) return std::unexpected(text.error());
  auto root = parse_toml(*text, file);
  if (!root) return std::unexpected(root.error());
  const toml::table* table = root->get_as<toml::table>("corner_model");
  if (!table) return fail(fmt::format("corner calibration '{}': no [corner_model] table", file));
  ConfigErrors errors;
  TableReader r(*table, "corner_model", corner_calibration_spec(), file, errors);
  const CornerNoiseModel model = read_corner_model_keys(r, CornerNoiseModel{});
  if (!errors.empty()) return fail(errors.joined());
  return model;
}

namespace {
// Every fiducial device of a covtrackd config file, read as the daemon reads it; every
// problem of those devices' tables in one error.
Result<std::vector<FiducialConfig>> read_fiducial_devices(const std::string& config_file) {
  auto text = read_config_text(config_file);
  if (!text) return std::unexpected(text.error());
  auto root = parse_toml(*text, config_file);
  if (!root) return std::unexpected(root.error());
  ConfigErrors errors;
  std::vector<FiducialConfig> out;
  if (const toml::table* devices = root->get_as<toml::table>("devices"))
    for (const auto& [name, node] : *devices) {
      const toml::table* device = node.as_table();
      if (!device || device->get_as<std::string>("type") == nullptr ||
          device->get_as<std::string>("type")->get() != "fiducial")
        continue;
      const std::string device_name(name.str());
      TableReader r(*device, "devices." + device_name, fiducial_device_spec(), config_file, errors);
      out.push_back(*read_fiducial_config(r, device_name));
    }
  if (!errors.empty()) return fail(errors.joined());
  return out;
}
}  // namespace

Result<std::vector<TagBundle>> read_config_bundles(const std::string& config_file) {
  auto devices = read_fiducial_devices(config_file);
  if (!devices) return std::unexpected(devices.error());
  std::vector<TagBundle> bundles;
  for (const FiducialConfig& c : *devices) bundles.insert(bundles.end(), c.bundles.begin(), c.bundles.end());
  return bundles;
}

Result<FiducialConfig> read_config_device(const std::string& config_file, const std::string& device) {
  auto devices = read_fiducial_devices(config_file);
  if (!devices) return std::unexpected(devices.error());
  std::vector<std::string> names;
  for (const FiducialConfig& c : *devices) {
    if (c.device == device) return c;
    names.push_back(c.device);
  }
  return fail(fmt::format("{}: no fiducial device '{}' (its fiducial devices: {})", config_file, device,
                          names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "))));
}

}  // namespace covtrack::fiducial
