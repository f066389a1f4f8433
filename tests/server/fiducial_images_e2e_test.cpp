// Camera frames from the daemon: a fiducial device with publish_images on (the rendered
// demo frames) sends every n-th frame on covtrack/image/<device>, stamped with the
// measurement time of the poses measured in it (a separate covtrackd process, inside a
// private network namespace).
#include <gtest/gtest.h>

#include <map>
#include <set>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>

#include <covtrack/image_t.hpp>
#include <covtrack/pose_cov_t.hpp>

#include "daemon_process.hpp"

using namespace covtrack;

namespace {

class Collector {
 public:
  explicit Collector(const std::string& url) : lcm_(url) {
    lcm_.subscribe("covtrack/pose/.*", &Collector::on_pose, this)->setQueueCapacity(100000);
    lcm_.subscribe("covtrack/image/.*", &Collector::on_image, this)->setQueueCapacity(1000);
  }
  void run_for(double seconds) { covtrack::test::handle_for(lcm_, seconds); }
  std::set<std::int64_t> pose_times;
  std::vector<image_t> images;
  std::set<std::string> image_channels;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
    pose_times.insert(m->measurement_time_us);
  }
  void on_image(const lcm::ReceiveBuffer*, const std::string& channel, const image_t* m) {
    image_channels.insert(channel);
    images.push_back(*m);
  }
  lcm::LCM lcm_;
};

}  // namespace

TEST(FiducialImagesE2e, EveryNthFrameArrivesWithItsPosesTime) {
  const std::string url = "udpm://239.255.76.67:7743?ttl=0";
  const std::string config = R"(
[devices.eye]
type = "fiducial"
parent_frame = "camera"
source = ")" COVTRACK_BINARY_DIR R"(/fiducial_demo/frame_%04d.png"
calibration = ")" COVTRACK_SOURCE_DIR R"(/config/cameras/rendered_640x480.yml"
rate_hz = 30
publish_images = true
image_every_n = 3
image_jpeg_quality = 70

[[devices.eye.tags]]
id = 0
size_m = 0.16
)";
  Collector collector(url);
  test::DaemonProcess daemon(config, url);
  collector.run_for(3.0);
  int status = 0;
  EXPECT_GE(daemon.stop(SIGTERM, status), 0);

  const std::size_t frames = collector.pose_times.size();  // one tag: one time per frame
  std::printf("frames with poses %zu, images %zu\n", frames, collector.images.size());
  ASSERT_GT(frames, 15u);
  EXPECT_EQ(collector.image_channels, std::set<std::string>{"covtrack/image/eye"});
  // One in three frames, give or take the frames in flight when the daemon stopped.
  EXPECT_NEAR(double(collector.images.size()), frames / 3.0, 2.0);
  for (const image_t& image : collector.images) {
    EXPECT_TRUE(collector.pose_times.count(image.measurement_time_us))
        << "image at " << image.measurement_time_us << " us matches no pose's time";
    EXPECT_EQ(image.device, "eye");
    EXPECT_EQ(image.encoding, "jpeg");
    EXPECT_EQ(image.size, static_cast<std::int32_t>(image.data.size()));
    const cv::Mat decoded = cv::imdecode(image.data, cv::IMREAD_COLOR);
    ASSERT_FALSE(decoded.empty());
    EXPECT_EQ(decoded.cols, 640);
    EXPECT_EQ(decoded.rows, 480);
  }
}
