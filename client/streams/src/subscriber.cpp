#include "covtrack/client/subscriber.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cmath>
#include <mutex>
#include <regex>
#include <thread>
#include <unordered_map>

#include <fmt/format.h>

#include "covtrack/client/pose_validation.hpp"
#include "covtrack/client/sequence_tracker.hpp"
#include "covtrack/protocol/channel_messages.hpp"
#include "covtrack/protocol/channel_pattern.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "covtrack/protocol/message_auth.hpp"
#include "covtrack/protocol/replay_guard.hpp"
#include "udpm_receiver.hpp"

namespace covtrack::client {
namespace {
// How often, at the least, the dispatch thread wakes to check streams and devices for silence.
constexpr int kStaleCheckMs = 20;
// The longest stop() spends on messages already received.
constexpr std::int64_t kDrainUs = 200'000;
// Heartbeats come once per second per device; this only absorbs a burst at start-up.
constexpr int kStatusQueueCapacity = 1000;
// Batches of datagrams read per wake-up before the clock is checked for silence.
constexpr int kBatchesPerWake = 16;
// The largest SubscriberOptions::auth_max_age_s: a day is no protection against replays already.
constexpr double kMaxAuthAgeS = 86400;
// Channels whose verdict is remembered; the bus has few, a flood of made-up ones resets it.
constexpr std::size_t kChannelVerdicts = 4096;

struct Callback {
  std::regex pattern;
  Subscriber::PoseCallback function;
};
// Replaced, never modified, so the dispatch thread can call a snapshot without a lock.
using CallbackList = std::vector<Callback>;

// Lets an unordered_map<std::string, ...> be searched with a string_view (no allocation).
struct TextHash {
  using is_transparent = void;
  std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
};

}  // namespace

// Receives through one of two paths: for udpm:// URLs its own UdpmReceiver, read on the
// dispatch thread; otherwise (memq://, an attached instance) an lcm::LCM instance.
struct Subscriber::Impl final : UdpmReceiver::Handler {
  SubscriberOptions options;
  std::shared_ptr<lcm::LCM> lcm;  // the LCM path
  std::vector<lcm::Subscription*> subscriptions;
  std::unique_ptr<UdpmReceiver> udpm;  // the udpm path
  std::regex stream_pattern;           // options.pattern, over "device/sensor"
  std::unordered_map<std::string, bool, TextHash, std::equal_to<>> channel_verdicts;  // udpm: wants()
  int wake_fd = -1;
  std::jthread thread;

  mutable std::mutex mutex;  // guards streams, devices, rejections and auth
  struct Stream {
    explicit Stream(std::int64_t window) : sequence(window) {}
    StreamState state;
    SequenceTracker sequence;  // fed every decoded message, accepted or not
    std::int64_t last_accept_us = 0;
    // The callbacks whose pattern matches this stream, for `matched_for`: regex matching
    // once per stream and callback list, not once per message.
    std::shared_ptr<const CallbackList> matched_for;
    std::vector<const Subscriber::PoseCallback*> matched;
  };
  std::map<std::string, Stream> streams;  // by "device/sensor"; never erased, so pointers stay valid
  // The same streams by pose channel, for the dispatch thread alone (no lock): the channel
  // is parsed and its "device/sensor" key built once per stream, not once per message.
  std::unordered_map<std::string, Stream*, TextHash, std::equal_to<>> stream_by_channel;
  std::map<std::string, DeviceTracker> devices;  // by device name
  RejectionTally rejections;  // every rejected message, of any channel
  std::optional<AuthKey> key;
  std::optional<ReplayGuard> replay_guard;  // with a key; the dispatch thread's only
  AuthCounters auth;

  std::mutex callbacks_mutex;
  std::shared_ptr<const CallbackList> callbacks = std::make_shared<CallbackList>();

  ~Impl() {
    if (wake_fd >= 0) ::close(wake_fd);
  }

  // A shared instance outlives us: it must not call back into a destroyed Impl.
  void unsubscribe() {
    for (auto* s : subscriptions) lcm->unsubscribe(s);
    subscriptions.clear();
  }

  std::shared_ptr<const CallbackList> callback_snapshot() {
    std::lock_guard lock(callbacks_mutex);
    return callbacks;
  }

  // Counts a message that no stream can own: its channel is not a stream's, or a heartbeat.
  void reject_unowned(const std::string& channel, const WireRejection& why) {
    std::lock_guard lock(mutex);
    rejections.add(to_string(why.fault), channel, why.describe());
  }

  // The message without its trailer when it needs none (no key) or is authentic and
  // fresh; nothing, counted, otherwise.
  std::optional<std::span<const std::byte>> authentic(std::string_view channel, std::span<const std::byte> bytes) {
    if (!key) return bytes;
    const auto checked = authenticate(*key, channel, bytes);
    const auto replay = checked ? replay_guard->check(channel, checked->trailer, now_us()) : std::nullopt;
    std::lock_guard lock(mutex);
    if (!checked) {
      ++(checked.error() == AuthFault::Missing ? auth.unauthenticated : auth.forged);
      rejections.add(to_string(checked.error()), std::string(channel),
                     checked.error() == AuthFault::Missing ? "no authentication trailer"
                                                           : "the MAC does not match (another key, or altered bytes)");
      return std::nullopt;
    }
    if (replay) {
      ++auth.replayed;
      rejections.add("replayed", std::string(channel), *replay);
      return std::nullopt;
    }
    ++auth.authenticated;
    return checked->message;
  }

  void on_pose_bytes(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (auto bytes = authentic(channel, bytes_of(rbuf->data, rbuf->data_size))) on_pose(channel, *bytes);
  }
  void on_status_bytes(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (auto bytes = authentic(channel, bytes_of(rbuf->data, rbuf->data_size))) on_status(channel, *bytes);
  }

  // UdpmReceiver::Handler: the channels LCM's subscriptions would let in (below, attach()).
  bool wants(std::string_view channel) override {
    if (auto it = channel_verdicts.find(channel); it != channel_verdicts.end()) return it->second;
    bool wanted = channel.starts_with(kStatusPrefix);
    if (channel.starts_with(kPosePrefix)) {
      const auto stream = channel.substr(kPosePrefix.size());
      wanted = std::regex_match(stream.begin(), stream.end(), stream_pattern);
    }
    if (channel_verdicts.size() >= kChannelVerdicts) channel_verdicts.clear();
    channel_verdicts.emplace(channel, wanted);
    return wanted;
  }
  void on_message(std::string_view channel, std::span<const std::byte> payload) override {
    const auto bytes = authentic(channel, payload);
    if (!bytes) return;
    if (channel.starts_with(kPosePrefix))
      on_pose(channel, *bytes);
    else
      on_status(channel, *bytes);
  }
  void on_malformed(const std::string& from, const lcm_wire::DatagramRejection& why) override {
    std::lock_guard lock(mutex);
    rejections.add(lcm_wire::to_string(why.fault), "datagram from " + from, why.describe());
  }

  // The stream a pose channel names, made at its first message; null when the channel
  // names none. Dispatch thread only.
  Stream* stream_of(std::string_view channel) {
    if (auto it = stream_by_channel.find(channel); it != stream_by_channel.end()) return it->second;
    const auto id = parse_pose_channel(channel);
    if (!id) return nullptr;
    Stream* s = nullptr;
    {
      std::lock_guard lock(mutex);
      s = &streams.try_emplace(id->key(), options.sequence_window).first->second;
      s->state.id = *id;
    }
    if (stream_by_channel.size() >= kChannelVerdicts) stream_by_channel.clear();
    stream_by_channel.emplace(channel, s);
    return s;
  }

  void on_pose(std::string_view channel, std::span<const std::byte> bytes) {
    const std::int64_t now = now_us();
    const auto decoded = decode_pose(channel, bytes);
    Stream* const stream = stream_of(channel);
    if (!stream) return reject_unowned(std::string(channel), decoded.error());
    std::optional<std::pair<std::string, std::string>> rejection;  // reason, description
    if (!decoded)
      rejection.emplace(to_string(decoded.error().fault), decoded.error().describe());
    else if (auto invalid = rejection_reason(*decoded))
      rejection.emplace("invalid pose", *invalid);

    const auto current_callbacks = callback_snapshot();
    const std::vector<const PoseCallback*>* to_call = nullptr;
    {
      std::lock_guard lock(mutex);
      Stream& s = *stream;
      // A decoded message names this stream (decode_pose checks it), so its sequence
      // number counts even if its values are rejected: it arrived, it is no loss.
      auto order = SequenceTracker::Verdict::First;
      if (decoded) {
        const auto r = s.sequence.classify(decoded->sequence);
        order = r.verdict;
        s.state.counters.lost += r.lost;
        s.state.counters.restarts += order == SequenceTracker::Verdict::Restart;
      }
      if (rejection) {
        ++s.state.counters.rejected;
        s.state.last_rejection = rejection->second;
        rejections.add(rejection->first, std::string(channel), rejection->second);
        return;
      }
      if (order == SequenceTracker::Verdict::Foreign) {
        ++s.state.counters.foreign;
        return;
      }
      s.last_accept_us = now;
      s.state.stale = false;
      ++s.state.counters.received;
      s.state.latest = to_tracked_transform(*decoded, now);
      to_call = &matching_callbacks(s, current_callbacks);
    }
    // Outside the lock: a callback may read latest() or register another callback.
    // current_callbacks keeps the functions alive while they run. Only this thread writes
    // a stream's latest report and its matched callbacks, so both are read without a copy.
    for (const PoseCallback* cb : *to_call) (*cb)(*stream->state.latest);
  }

  // The callbacks of `current` whose pattern matches the stream (call with mutex held).
  static const std::vector<const PoseCallback*>& matching_callbacks(
      Stream& s, const std::shared_ptr<const CallbackList>& current) {
    if (s.matched_for != current) {
      s.matched.clear();
      for (const auto& cb : *current)
        if (std::regex_match(s.state.id.key(), cb.pattern)) s.matched.push_back(&cb.function);
      s.matched_for = current;
    }
    return s.matched;
  }

  void on_status(std::string_view channel, std::span<const std::byte> bytes) {
    const std::int64_t now = now_us();
    const auto decoded = decode_status(channel, bytes);
    if (!decoded) return reject_unowned(std::string(channel), decoded.error());
    std::lock_guard lock(mutex);
    devices[decoded->device].on_heartbeat(*decoded, now);
  }

  // Streams without a message for stale_after_s are stale. A device without a heartbeat
  // for DeviceTracker::kMissedHeartbeats periods is unreachable: its streams are reported
  // LOST, through latest() and the callbacks, so a dead daemon is told from a quiet one.
  void check_silence() {
    const std::int64_t now = now_us();
    const std::int64_t limit = now - static_cast<std::int64_t>(options.stale_after_s * 1e6);
    const auto current_callbacks = callback_snapshot();
    std::vector<std::pair<TrackedTransform, std::vector<const PoseCallback*>>> to_call;
    {
      std::lock_guard lock(mutex);
      for (auto& [key, s] : streams)
        if (!s.state.stale && s.last_accept_us > 0 && s.last_accept_us < limit) {
          s.state.stale = true;
          ++s.state.counters.stale;
        }
      for (auto& [name, device] : devices) {
        if (!device.check(now)) continue;
        for (auto& [key, s] : streams)
          if (s.state.id.device == name && s.state.latest && !s.state.latest->device_unreachable) {
            s.state.latest = unreachable(*s.state.latest, now);
            to_call.emplace_back(*s.state.latest, matching_callbacks(s, current_callbacks));
          }
      }
    }
    for (const auto& [report, callbacks] : to_call)
      for (const PoseCallback* cb : callbacks) (*cb)(report);
  }

  // The last report of a stream whose device is unreachable, made LOST.
  static TrackedTransform unreachable(TrackedTransform last, std::int64_t now) {
    last.status = TrackingStatus::Lost;
    last.covariance = lost_covariance();  // as a LOST message arrives (TrackedTransform)
    last.receive_time_us = now;
    last.device_unreachable = true;
    return last;
  }

  // Reads what has arrived: LCM's queue, or the udpm socket in batches.
  // Returns whether there was anything.
  bool receive() {
    if (udpm) return udpm->read_available(*this, kBatchesPerWake) > 0;
    return lcm->handleTimeout(0) > 0;
  }

  // Neither LCM's handle() nor a wait on the socket can be interrupted: poll the
  // descriptor together with wake_fd, which stop() writes to.
  void dispatch(std::stop_token stop) {
    pollfd fds[2] = {{udpm ? udpm->fd() : lcm->getFileno(), POLLIN, 0}, {wake_fd, POLLIN, 0}};
    std::int64_t next_stale_check = 0;
    while (!stop.stop_requested()) {
      const int n = ::poll(fds, 2, kStaleCheckMs);
      if (n > 0 && (fds[0].revents & POLLIN)) receive();
      // At high rates poll() never times out: check staleness on a clock, not per wake-up.
      if (const std::int64_t now = now_us(); now >= next_stale_check) {
        check_silence();
        next_stale_check = now + kStaleCheckMs * 1000;
      }
    }
    // What had already arrived when told to stop still counts (a program's summary at
    // exit covers everything sent before it was stopped); bounded, as a stream never ends.
    const std::int64_t drain_end = now_us() + kDrainUs;
    while (now_us() < drain_end && receive()) {
    }
  }
};

Subscriber::Subscriber(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Subscriber::~Subscriber() { stop(); }

Result<std::unique_ptr<Subscriber>> Subscriber::open(const SubscriberOptions& options) {
  auto re = compile_channel_pattern(options.pattern);
  if (!re) return std::unexpected(re.error());
  const std::string url = effective_lcm_url(options.lcm_url);
  if (url.starts_with("udpm://")) {
    if (auto ok = check_lcm_url(url); !ok) return std::unexpected(ok.error());
    auto receiver = UdpmReceiver::open(url);
    if (!receiver) return std::unexpected(receiver.error());
    auto impl = std::make_unique<Impl>();
    impl->options = options;
    impl->stream_pattern = std::move(*re);
    impl->udpm = std::move(*receiver);
    return start(std::move(impl));
  }
  auto lcm = open_lcm(url);
  if (!lcm) return std::unexpected(lcm.error());
  return attach(std::shared_ptr<lcm::LCM>(std::move(*lcm)), options);
}

Result<std::unique_ptr<Subscriber>> Subscriber::attach(std::shared_ptr<lcm::LCM> lcm,
                                                       const SubscriberOptions& options) {
  if (auto re = compile_channel_pattern(options.pattern); !re) return std::unexpected(re.error());
  if (!lcm || !lcm->good()) return fail("Subscriber::attach: the LCM instance is not usable");
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->lcm = std::move(lcm);
  // LCM anchors a subscription's regex at both ends: "whole match" comes for free.
  auto* poses = impl->lcm->subscribe(std::string(kPosePrefix) + "(" + options.pattern + ")",
                                     &Impl::on_pose_bytes, impl.get());
  poses->setQueueCapacity(options.queue_capacity);
  auto* status = impl->lcm->subscribe(std::string(kStatusPrefix) + ".*", &Impl::on_status_bytes, impl.get());
  status->setQueueCapacity(kStatusQueueCapacity);
  impl->subscriptions = {poses, status};
  return start(std::move(impl));
}

Result<std::unique_ptr<Subscriber>> Subscriber::start(std::unique_ptr<Impl> impl) {
  if (const std::string key_file = effective_key_file(impl->options.key_file); !key_file.empty()) {
    auto key = load_auth_key(key_file);
    const double max_age_s = impl->options.auth_max_age_s;
    if (!key || !(max_age_s > 0 && max_age_s <= kMaxAuthAgeS)) {  // also refuses NaN
      impl->unsubscribe();
      return key ? fail(fmt::format("Subscriber: auth_max_age_s must be above 0 and at most {} s, got {}",
                                    kMaxAuthAgeS, max_age_s))
                 : std::unexpected(key.error());
    }
    impl->key = *key;
    impl->replay_guard.emplace(impl->options.auth_max_age_s);
    impl->auth.key_file = key_file;
  }
  impl->wake_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (impl->wake_fd < 0) {
    impl->unsubscribe();
    return fail("Subscriber: eventfd failed");
  }
  Impl* raw = impl.get();
  raw->thread = std::jthread([raw](std::stop_token stop) { raw->dispatch(stop); });
  return std::unique_ptr<Subscriber>(new Subscriber(std::move(impl)));
}

Result<void> Subscriber::on_pose(const std::string& pattern, PoseCallback callback) {
  auto re = compile_channel_pattern(pattern);
  if (!re) return std::unexpected(re.error());
  std::lock_guard lock(impl_->callbacks_mutex);
  auto next = std::make_shared<CallbackList>(*impl_->callbacks);
  next->push_back({std::move(*re), std::move(callback)});
  impl_->callbacks = std::move(next);
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
  out.reserve(impl_->streams.size());
  for (const auto& [key, s] : impl_->streams) out.push_back(s.state);
  return out;
}

std::map<std::string, device_status_t> Subscriber::device_statuses() const {
  std::lock_guard lock(impl_->mutex);
  std::map<std::string, device_status_t> out;
  for (const auto& [name, device] : impl_->devices) out.emplace(name, device.state().status);
  return out;
}

std::map<std::string, DeviceState> Subscriber::devices() const {
  std::lock_guard lock(impl_->mutex);
  std::map<std::string, DeviceState> out;
  for (const auto& [name, device] : impl_->devices) out.emplace(name, device.state());
  return out;
}

RejectionTally Subscriber::rejections() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->rejections;
}

std::optional<AuthCounters> Subscriber::authentication() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->key) return std::nullopt;
  return impl_->auth;
}

void Subscriber::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  impl_->thread.request_stop();
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(impl_->wake_fd, &one, sizeof one);
  impl_->thread.join();
  impl_->unsubscribe();
}

std::optional<ReceiveBufferSize> Subscriber::receive_buffer() const {
  if (!impl_->udpm) return std::nullopt;
  return impl_->udpm->receive_buffer();
}

}  // namespace covtrack::client
