// Built by sdk_install_test.sh with nothing but `pkg-config --cflags --libs covtrack`:
// counts a log's good events (covtrack::log) and the pose messages that decode.
#include <cstdio>
#include <type_traits>

#include <covtrack/client/camera.hpp>  // the camera model's old path, kept for SDK users
#include <covtrack/lcmlog/log_reader.hpp>
#include <covtrack/protocol/channel_messages.hpp>

static_assert(std::is_same_v<covtrack::client::Camera, covtrack::Camera>);

int main(int argc, char** argv) {
  auto log = covtrack::lcmlog::LogReader::open(argc > 1 ? argv[1] : "");
  if (!log) return std::fprintf(stderr, "%s\n", log.error().message.c_str()), 1;
  long events = 0, poses = 0;
  while (auto event = log->next()) {
    ++events;
    if (covtrack::decode_pose(event->channel, event->payload)) ++poses;
  }
  std::printf("%ld events, %ld poses\n", events, poses);
}
