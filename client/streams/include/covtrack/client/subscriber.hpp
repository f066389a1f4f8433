#pragma once
// Receives covtrack pose streams and device heartbeats on one dispatch thread.
//
//   auto sub = covtrack::client::Subscriber::open({.lcm_url = url, .pattern = "sim/.*"});
//   if (!sub) { report(sub.error().message); return; }
//   (*sub)->on_pose(".*", [](const TrackedTransform& t) { ... });   // dispatch thread
//   auto head = (*sub)->latest({"sim", "head"});                        // any thread
//
// Transport: for a udpm:// URL (LCM's default) the dispatch thread reads the multicast
// socket itself, in batches, speaking LCM's wire format (any LCM publisher reaches it,
// fragmented messages included); there is no LCM receive thread and no queue between the
// two. Its socket receive buffer defaults to 4 MiB (receive_buffer()). Other URLs
// (memq://, ...) and attach() go through an lcm::LCM instance.
//
// Thread safety: every const method, on_pose() and stop() may be called from any thread.
// Callbacks run on the dispatch thread, one at a time, in arrival order; they must return
// quickly (they delay every stream) and must not throw (an exception escaping a callback
// ends the process). A callback may call on_pose() and the const methods, but not stop()
// nor destroy the Subscriber.
//
// What is delivered: a message is rejected (counted, never passed to latest() or a
// callback) when it fails the wire checks (decode_pose(): type, lengths, names; a
// malformed message cannot end the process), names another device/sensor than its
// channel, has an unknown status or convention, a non-finite position, a non-unit
// quaternion or a covariance that is non-finite, asymmetric or not positive
// semi-definite. LOST messages skip the covariance checks: see TrackedTransform.
// Heartbeats are checked the same way (decode_status()). Every rejection is counted by
// its reason in rejections(); those of a stream's channel also in its counters.
//
// Authentication (docs/authentication.md): given a key file, every message must carry a
// valid trailer (message_auth.hpp), checked before anything else; a message without one,
// with one that fails its MAC (a forgery, another key, altered bytes) or that was seen
// before or sent more than auth_max_age_s ago (a replay) is refused and counted in
// authentication() and rejections(), not in a stream's counters: it never creates a
// stream nor counts as its loss. Without a key, trailers are ignored.
//
// Silence: a stream without a message for stale_after_s is stale (it keeps its last
// value). A device whose heartbeats were heard and then stop for 3 of their periods is
// unreachable (devices()): each of its streams is reported LOST at once, through latest()
// and the callbacks, with device_unreachable set, until its next message.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <covtrack/device_status_t.hpp>
#include <lcm/lcm-cpp.hpp>

#include "covtrack/client/device_tracker.hpp"
#include "covtrack/client/receive_buffer.hpp"
#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/protocol/rejection_tally.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

struct SubscriberOptions {
  std::string lcm_url = {};      // empty: $LCM_DEFAULT_URL, else LCM's default
  std::string pattern = ".*";    // over "device/sensor" (protocol/channel_pattern.hpp)
  double stale_after_s = 0.5;    // a stream is stale after this long without a message
  // Through lcm::LCM (not udpm://): LCM drops the newest message silently when a
  // subscription's queue is full (default 30); this is that queue's length, large enough
  // for a burst of several seconds. On udpm:// the socket's receive buffer is the queue:
  // its size is the URL's recv_buf_size.
  int queue_capacity = 100000;
  // The largest forward jump of a stream's sequence still counted as loss; beyond it, or
  // backwards, a message is off the stream's track (SequenceTracker).
  std::int64_t sequence_window = 1000;
  // The daemon's shared key (its [auth] key_file); empty: $COVTRACK_KEY_FILE, and when
  // that is unset too, no authentication.
  std::string key_file = {};
  // With a key: the oldest an authenticated message may be by its sender's clock (and
  // the farthest in the future), so a message captured earlier cannot be replayed from
  // a daemon instance this subscriber never heard from; hosts' clocks must agree within it.
  // Above 0, at most a day.
  double auth_max_age_s = 2.0;
};

// With a key: what authentication let through and refused, by kind.
struct AuthCounters {
  std::string key_file;
  std::int64_t authenticated = 0;    // a valid MAC, not a replay: then checked as any message
  std::int64_t unauthenticated = 0;  // no trailer
  std::int64_t forged = 0;           // a trailer whose MAC fails
  std::int64_t replayed = 0;         // seen before, or sent outside auth_max_age_s
};

// Every message on a stream's channel is received, rejected or foreign, exactly one
// (with a key: every authenticated one; see authentication()).
struct StreamCounters {
  std::int64_t received = 0;  // accepted and delivered
  std::int64_t lost = 0;      // sequence numbers skipped by a forward jump within sequence_window
  std::int64_t rejected = 0;  // malformed or invalid messages (never delivered)
  // Valid messages off the stream's sequence (a duplicate, a second publisher's, a forged
  // one; and the SequenceTracker::kConfirm - 1 before a restart is followed): never delivered.
  std::int64_t foreign = 0;
  std::int64_t restarts = 0;  // times the stream's sequence started again (a daemon restart)
  std::int64_t stale = 0;     // times the stream went stale
};

struct StreamState {
  StreamId id;
  std::optional<TrackedTransform> latest;  // the last accepted message
  StreamCounters counters;
  bool stale = false;          // no accepted message for stale_after_s (checked every ~20 ms)
  std::string last_rejection;  // why the last rejected message was rejected
};

class Subscriber {
 public:
  using PoseCallback = std::function<void(const TrackedTransform&)>;

  // Opens its own LCM instance. Fails at once, with how to fix it, on an unusable URL
  // (no multicast route: no 10 s LCM self-test hang), a bad pattern or key file.
  static Result<std::unique_ptr<Subscriber>> open(const SubscriberOptions& options);

  // Receives on an LCM instance the caller shares, e.g. one memq:// instance that the
  // same process publishes on (memq only reaches its own instance). options.lcm_url is
  // ignored. The Subscriber's thread is then the only one that may call handle() on it,
  // and only one Subscriber may attach to an instance.
  static Result<std::unique_ptr<Subscriber>> attach(std::shared_ptr<lcm::LCM> lcm,
                                                    const SubscriberOptions& options);
  ~Subscriber();
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  // Calls `callback` on the dispatch thread for every accepted message of the streams
  // whose "device/sensor" wholly matches `pattern` (only streams the subscriber's own
  // pattern lets in ever arrive). Returns an error for a bad regular expression.
  Result<void> on_pose(const std::string& pattern, PoseCallback callback);

  std::optional<TrackedTransform> latest(const StreamId& id) const;
  std::optional<StreamState> stream(const StreamId& id) const;  // nothing if never seen
  std::vector<StreamState> streams() const;  // ordered by device/sensor
  // The last heartbeat (covtrack/status/<device>) of each device, by device name.
  std::map<std::string, device_status_t> device_statuses() const;
  // Each device as its heartbeats tell it (reachable, publishers, restarts), by name.
  std::map<std::string, DeviceState> devices() const;
  // Every message rejected so far (poses, heartbeats, channels that name no stream, and
  // on udpm:// datagrams that are not LCM's format).
  RejectionTally rejections() const;
  // With a key, the authentication counters; nothing without one.
  std::optional<AuthCounters> authentication() const;

  // On udpm://, the socket receive buffer asked for and granted, with a note when
  // net.core.rmem_max capped it (a program should show the note); nothing otherwise.
  std::optional<ReceiveBufferSize> receive_buffer() const;

  // Ends the dispatch thread, after it has handled what had already arrived (for at
  // most 0.2 s); idempotent, prompt when no message arrives. After it no callback runs;
  // latest() and the counters keep their last values.
  void stop();

 private:
  struct Impl;
  explicit Subscriber(std::unique_ptr<Impl> impl);
  static Result<std::unique_ptr<Subscriber>> start(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace covtrack::client
