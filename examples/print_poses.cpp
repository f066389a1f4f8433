// Subscribes to covtrack's pose streams and prints, once a second, each stream's latest
// position and its 1-sigma errors (square roots of the covariance's diagonal).
//   print_poses ['optical/.*' [SECONDS]]    (LCM_DEFAULT_URL chooses the network)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <thread>

#include <covtrack/client/subscriber.hpp>

int main(int argc, char** argv) {
  covtrack::client::SubscriberOptions options;
  if (argc > 1) options.pattern = argv[1];
  const int seconds = argc > 2 ? std::stoi(argv[2]) : 10;
  auto subscriber = covtrack::client::Subscriber::open(options);
  if (!subscriber) {
    std::fprintf(stderr, "print_poses: %s\n", subscriber.error().message.c_str());
    return 1;
  }
  for (int s = 0; s < seconds; ++s) {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    for (const auto& stream : (*subscriber)->streams()) {
      if (!stream.latest) continue;
      const auto& pose = *stream.latest;
      const auto& p = pose.T_parent_child.translation();
      std::printf("%s %s in %s: [%+.3f %+.3f %+.3f] m", stream.id.key().c_str(),
                  covtrack::to_string(pose.status), pose.parent_frame.c_str(), p.x(), p.y(), p.z());
      if (pose.lost()) {
        std::printf("  (no covariance while lost)\n");
        continue;
      }
      const auto sigma = pose.covariance.diagonal().cwiseSqrt();  // BODY: x y z (m), rx ry rz (rad)
      std::printf("  sigma xyz [%.2f %.2f %.2f] mm  rxyz [%.2f %.2f %.2f] deg  %lld received\n",
                  1e3 * sigma[0], 1e3 * sigma[1], 1e3 * sigma[2], sigma[3] * 180 / std::numbers::pi,
                  sigma[4] * 180 / std::numbers::pi, sigma[5] * 180 / std::numbers::pi,
                  static_cast<long long>(stream.counters.received));
    }
    std::fflush(stdout);
  }
  (*subscriber)->stop();
}
