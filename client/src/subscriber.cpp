#include "covtrack/client/subscriber.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <mutex>
#include <regex>
#include <thread>

#include <covtrack/pose_cov_t.hpp>

#include "covtrack/client/pose_validation.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/lcm_url.hpp"

namespace covtrack::client {
namespace {
// How often, at the least, the dispatch thread wakes to mark streams stale.
constexpr int kStaleCheckMs = 20;

Result<std::regex> compile(const std::string& pattern) {
  try {
    return std::regex(pattern, std::regex::extended);
  } catch (const std::regex_error& e) {
    return fail("bad stream pattern '" + pattern + "': " + e.what());
  }
}
}  // namespace

struct Subscriber::Impl {
  SubscriberOptions options;
  std::unique_ptr<lcm::LCM> lcm;
  int wake_fd = -1;
  std::jthread thread;

  mutable std::mutex mutex;
  struct Stream {
    StreamState state;
    std::int64_t last_sequence = -1;
    std::int64_t last_receive_us = 0;
  };
  std::map<std::string, Stream> streams;  // by "device/sensor"
  std::map<std::string, device_status_t> statuses;

  std::mutex callbacks_mutex;
  std::vector<std::pair<std::regex, PoseCallback>> callbacks;

  ~Impl() {
    if (wake_fd >= 0) ::close(wake_fd);
  }

  void on_pose_bytes(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const std::int64_t now = now_us();
    const auto id = parse_pose_channel(channel);
    if (!id) return;  // matched the regex but is not a well-formed stream name
    pose_cov_t msg;
    std::optional<std::string> reason;
    if (msg.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0)
      reason = "malformed message (" + std::to_string(rbuf->data_size) + " bytes)";
    else if (msg.device != id->device || msg.sensor != id->sensor)
      reason = "device/sensor '" + msg.device + "/" + msg.sensor + "' differ from the channel";
    else
      reason = rejection_reason(msg);

    std::optional<TrackedTransform> accepted;
    {
      std::lock_guard lock(mutex);
      Stream& s = streams[id->key()];
      s.state.id = *id;
      if (reason) {
        ++s.state.counters.rejected;
        s.state.last_rejection = *reason;
        return;
      }
      // A sequence going backwards is a daemon restart, not a loss.
      if (s.last_sequence >= 0 && msg.sequence > s.last_sequence + 1)
        s.state.counters.lost += msg.sequence - s.last_sequence - 1;
      s.last_sequence = msg.sequence;
      s.last_receive_us = now;
      s.state.stale = false;
      ++s.state.counters.received;
      s.state.latest = to_tracked_transform(msg, now);
      accepted = s.state.latest;
    }
    std::lock_guard lock(callbacks_mutex);
    const std::string key = id->key();
    for (auto& [re, cb] : callbacks)
      if (std::regex_match(key, re)) cb(*accepted);
  }

  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* msg) {
    std::lock_guard lock(mutex);
    statuses[msg->device] = *msg;
  }

  void mark_stale() {
    const std::int64_t limit = now_us() - static_cast<std::int64_t>(options.stale_after_s * 1e6);
    std::lock_guard lock(mutex);
    for (auto& [key, s] : streams)
      if (!s.state.stale && s.last_receive_us > 0 && s.last_receive_us < limit) {
        s.state.stale = true;
        ++s.state.counters.stale;
      }
  }

  // LCM's handle() cannot be interrupted: poll its descriptor together with wake_fd.
  void dispatch(std::stop_token stop) {
    pollfd fds[2] = {{lcm->getFileno(), POLLIN, 0}, {wake_fd, POLLIN, 0}};
    while (!stop.stop_requested()) {
      const int n = ::poll(fds, 2, kStaleCheckMs);
      if (n > 0 && (fds[0].revents & POLLIN)) lcm->handle();
      mark_stale();
    }
  }
};

Subscriber::Subscriber(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Subscriber::~Subscriber() { stop(); }

Result<std::unique_ptr<Subscriber>> Subscriber::open(const SubscriberOptions& options) {
  if (auto re = compile(options.pattern); !re) return std::unexpected(re.error());
  auto lcm = open_lcm(options.lcm_url);
  if (!lcm) return std::unexpected(lcm.error());
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->lcm = std::move(*lcm);
  impl->wake_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (impl->wake_fd < 0) return fail("eventfd failed");

  Impl* raw = impl.get();
  auto* poses = raw->lcm->subscribe(std::string(kPosePrefix) + "(" + options.pattern + ")",
                                    &Impl::on_pose_bytes, raw);
  poses->setQueueCapacity(options.queue_capacity);
  auto* status = raw->lcm->subscribe(std::string(kStatusPrefix) + ".*", &Impl::on_status, raw);
  status->setQueueCapacity(1000);
  raw->thread = std::jthread([raw](std::stop_token stop) { raw->dispatch(stop); });
  return std::unique_ptr<Subscriber>(new Subscriber(std::move(impl)));
}

Result<void> Subscriber::on_pose(const std::string& pattern, PoseCallback callback) {
  auto re = compile(pattern);
  if (!re) return std::unexpected(re.error());
  std::lock_guard lock(impl_->callbacks_mutex);
  impl_->callbacks.emplace_back(std::move(*re), std::move(callback));
  return {};
}

std::optional<TrackedTransform> Subscriber::latest(const StreamId& id) const {
  std::lock_guard lock(impl_->mutex);
  auto it = impl_->streams.find(id.key());
  if (it == impl_->streams.end()) return std::nullopt;
  return it->second.state.latest;
}

std::optional<StreamState> Subscriber::stream(const StreamId& id) const {
  std::lock_guard lock(impl_->mutex);
  auto it = impl_->streams.find(id.key());
  if (it == impl_->streams.end()) return std::nullopt;
  return it->second.state;
}

std::vector<StreamState> Subscriber::streams() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<StreamState> out;
  for (const auto& [key, s] : impl_->streams) out.push_back(s.state);
  return out;
}

std::map<std::string, device_status_t> Subscriber::device_statuses() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->statuses;
}

void Subscriber::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  impl_->thread.request_stop();
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(impl_->wake_fd, &one, sizeof one);
  impl_->thread.join();
}

}  // namespace covtrack::client
