#include "covtrack/devices/fiducial/fiducial_driver.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bundle_pose.hpp"
#include "fiducial_config.hpp"
#include "frame_source.hpp"
#include "raw_detection.hpp"
#include "tag_pose.hpp"

namespace covtrack::fiducial {
namespace {

// What the device status says beside RUNNING: nothing while a tag of the map is in
// view; otherwise that the camera works but sees none, and which other tags it sees (a
// wrong family or tag map shows here).
std::string view_detail(bool mapped_in_view, const std::set<int>& unmapped) {
  if (mapped_in_view) return {};
  if (unmapped.empty()) return "no tag in view";
  return fmt::format("no mapped tag in view (seen, not in the tag map: {})", fmt::join(unmapped, ", "));
}

class FiducialDriver final : public Driver {
 public:
  FiducialDriver(const FiducialConfig& config, DriverClock& clock) : config_(config), clock_(clock) {
    for (const auto& [id, size] : config_.tag_size_m) tags_[id] = {{id, size, Pose::Identity()}, std::nullopt};
    for (std::size_t b = 0; b < config_.bundles.size(); ++b)
      for (const BundleTag& t : config_.bundles[b].tags) tags_[t.id] = {t, b};
  }

  Result<void> run(SampleSink& sink, std::stop_token stop) override {
    try {
      return run_checked(sink, stop);
    } catch (const std::exception& e) {  // OpenCV throws cv::Exception on odd input
      return fail(fmt::format("{}: {}", config_.source, e.what()));
    }
  }

 private:
  Result<void> run_checked(SampleSink& sink, std::stop_token stop) {
    auto camera = load_camera(config_.calibration);
    if (!camera) return std::unexpected(camera.error());
    camera_ = *camera;
    auto detector = TagDetector::create(config_.detector);
    if (!detector) return std::unexpected(detector.error());
    detector_ = std::move(*detector);
    auto source = open_frame_source(config_.source, config_.loop);
    if (!source) return std::unexpected(source.error());

    using namespace std::chrono;
    const bool paced = !(*source)->is_camera() && config_.rate_hz > 0;
    const auto period = paced ? duration_cast<DriverClock::duration>(duration<double>(1.0 / config_.rate_hz))
                              : DriverClock::duration::zero();
    auto next = clock_.now();
    cv::Mat gray;
    for (std::uint32_t index = 0; !stop.stop_requested(); ++index) {
      if (paced) {
        next += period;
        if (!clock_.sleep_until(stop, next)) return {};
      }
      auto read = (*source)->next();
      if (!read) return std::unexpected(read.error());
      if (read->kind == FrameRead::Kind::End) {  // a file source played once: idle until stopped
        while (clock_.sleep_until(stop, clock_.now() + milliseconds(50))) {}
        return {};
      }
      if (read->kind == FrameRead::Kind::Damaged) {
        // Skipped, keeping its frame period, so the frames after it keep their pace.
        sink.count_error(fmt::format("damaged frame '{}': {}; skipped", read->name, read->problem));
        continue;
      }
      const cv::Mat& frame = read->image;
      const std::int64_t time_us = clock_.now_us();
      to_gray8(frame, gray);
      if (gray.cols != camera_.width_px || gray.rows != camera_.height_px)
        return fail(fmt::format("'{}': frame is {}x{} but the calibration '{}' is for {}x{}",
                                read->name.empty() ? config_.source : read->name, gray.cols,
                                gray.rows, config_.calibration, camera_.width_px, camera_.height_px));
      process(sink, gray, index, time_us);
      if (config_.publish_images && frames_published_++ % std::max(1, config_.image_every_n) == 0)
        publish_image(sink, frame, time_us);
    }
    return {};
  }

  void process(SampleSink& sink, const cv::Mat& gray, std::uint32_t index, std::int64_t time_us) {
    RawFrame raw{index, time_us, estimate_image_noise(gray), {}};
    std::set<std::string> posed;
    std::set<int> unmapped;
    std::map<int, int> copies;  // detections per mapped id in this frame
    std::map<std::size_t, std::vector<BundleObservation>> in_bundle;  // per bundle, its tags posed
    for (const Detection& det : detector_->detect(gray)) {
      const auto mapped = tags_.find(det.id);
      if (mapped == tags_.end()) {
        unmapped.insert(det.id);
        continue;
      }
      // One sensor per id: a second print of the same tag (or a false detection) cannot be
      // told from the first, so only the first is posed and the rest are reported below.
      if (++copies[det.id] > 1) continue;
      const MappedTag& tag = mapped->second;
      const CornerInputs inputs = measure_corner_inputs(gray, det, detector_->family(), raw.image_noise);
      const CornerNoise noise = config_.noise.noise(inputs);
      auto pose = estimate_tag_pose(camera_, det.corners_px, tag.tag.size_m, noise, config_.ambiguity_chi2);
      if (!pose) {
        sink.count_error(fmt::format("tag {}: {}", det.id, pose.error().message));
        continue;
      }
      RawTag rt{det, inputs.contrast, {pose->best}};
      if (pose->second) rt.solutions.push_back(*pose->second);
      raw.tags.push_back(rt);
      if (tag.bundle) in_bundle[*tag.bundle].push_back({tag.tag, *pose});
      if (!tag.bundle || config_.bundles[*tag.bundle].publish_tags) {
        const std::string sensor = fmt::format("tag{}", det.id);
        publish(sink, sensor, time_us, pose->best.T_camera_tag, pose->covariance, pose->ambiguous);
        posed.insert(sensor);
      }
    }
    for (const auto& [id, n] : copies)
      if (n > 1)
        sink.count_error(fmt::format("tag {} detected {} times in frame {}: only the first is posed (one "
                                     "sensor per id; print each tag once, or give the copies other ids)",
                                     id, n, index));
    std::vector<std::string> details;
    for (const auto& [b, observations] : in_bundle) {
      const std::string& name = config_.bundles[b].name;
      auto pose = estimate_bundle_pose(camera_, observations, config_.ambiguity_chi2, config_.bundle_consistency_chi2);
      if (!pose) {
        sink.count_error(fmt::format("bundle {}: {}", name, pose.error().message));
        continue;
      }
      publish(sink, name, time_us, pose->T_camera_bundle, pose->covariance, pose->degraded());
      posed.insert(name);
      if (pose->degraded()) details.push_back(fmt::format("{} DEGRADED: {}", name, pose->why_degraded));
    }
    // Sensors seen before and not now: LOST, so that a client tells "not seen" from "lost message".
    for (const auto& [sensor, last] : last_pose_) {
      if (posed.count(sensor)) continue;
      PoseSample s{sensor, config_.parent_frame, sensor, time_us};
      s.T_parent_child = last;
      s.covariance = lost_covariance();
      s.status = TrackingStatus::Lost;
      sink.pose(s);
    }
    if (const std::string view = view_detail(!copies.empty(), unmapped); !view.empty()) details.insert(details.begin(), view);
    sink.running(fmt::format("{}", fmt::join(details, "; ")));
    if (config_.publish_raw) {
      const auto bytes = encode_raw_frame(raw);
      sink.raw(ByteDirection::FromDevice, bytes.data(), bytes.size());
    }
  }

  void publish(SampleSink& sink, const std::string& sensor, std::int64_t time_us, const Pose& T, const Mat6& covariance,
               bool degraded) {
    PoseSample s{sensor, config_.parent_frame, sensor, time_us};
    s.T_parent_child = T;
    s.covariance = covariance;
    s.status = degraded ? TrackingStatus::Degraded : TrackingStatus::Ok;
    last_pose_[sensor] = T;
    sink.pose(s);
  }

  // The frame as captured (colour if it is), after its poses: a see-through view of the
  // log finds the picture at the same measurement time as the poses measured in it.
  void publish_image(SampleSink& sink, const cv::Mat& frame, std::int64_t time_us) {
    ImageSample image{time_us, frame.cols, frame.rows, "jpeg", {}};
    const std::vector<int> params = {cv::IMWRITE_JPEG_QUALITY, config_.image_jpeg_quality};
    cv::Mat eight_bit = frame;  // JPEG holds 8 bits per channel; deeper frames as the detector sees them
    if (frame.depth() != CV_8U) frame.convertTo(eight_bit, CV_8U);
    if (!cv::imencode(".jpg", eight_bit, image.bytes, params)) {
      sink.count_error(fmt::format("frame {}x{}: JPEG encoding failed", frame.cols, frame.rows));
      return;
    }
    sink.image(image);
  }

  FiducialConfig config_;
  DriverClock& clock_;
  Camera camera_;
  std::unique_ptr<TagDetector> detector_;
  std::uint64_t frames_published_ = 0;  // frames considered for publish_images (every n-th goes)
  // Every tag the driver poses: its size and place on its bundle, if it is in one.
  struct MappedTag {
    BundleTag tag;
    std::optional<std::size_t> bundle;
  };
  std::map<int, MappedTag> tags_;
  std::map<std::string, Pose> last_pose_;  // per sensor
};

}  // namespace

std::unique_ptr<Driver> make_fiducial_driver(const FiducialConfig& config, std::uint64_t, DriverClock& clock) {
  return std::make_unique<FiducialDriver>(config, clock);
}

}  // namespace covtrack::fiducial
