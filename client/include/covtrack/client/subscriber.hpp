#pragma once
// Receives covtrack pose streams and device heartbeats on one LCM dispatch thread.
//
// Thread safety: every const method may be called from any thread. Callbacks run on the
// dispatch thread, one at a time, and must return quickly (they delay every stream).
// A callback must not call stop() or destroy the Subscriber.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <covtrack/device_status_t.hpp>

#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

struct SubscriberOptions {
  std::string lcm_url;           // empty: $LCM_DEFAULT_URL, else LCM's default
  std::string pattern = ".*";    // regular expression over "device/sensor", whole match
  double stale_after_s = 0.5;    // a stream is stale after this long without a message
  // LCM drops the newest message silently when a subscription's queue is full (default
  // 30); this is that queue's length.
  int queue_capacity = 100000;
};

struct StreamCounters {
  std::int64_t received = 0;  // accepted messages
  std::int64_t lost = 0;      // missing sequence numbers
  std::int64_t rejected = 0;  // malformed or invalid messages (never delivered)
  std::int64_t stale = 0;     // times the stream went stale
};

struct StreamState {
  StreamId id;
  std::optional<TrackedTransform> latest;
  StreamCounters counters;
  bool stale = false;
  std::string last_rejection;  // why the last rejected message was rejected
};

class Subscriber {
 public:
  using PoseCallback = std::function<void(const TrackedTransform&)>;

  // Fails at once, with how to fix it, on an unusable URL or a bad pattern.
  static Result<std::unique_ptr<Subscriber>> open(const SubscriberOptions& options);
  ~Subscriber();
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  // Calls `callback` for every accepted message of the streams whose "device/sensor"
  // matches `pattern` (a subset of the subscriber's own pattern). Returns an error for a
  // bad regular expression.
  Result<void> on_pose(const std::string& pattern, PoseCallback callback);

  std::optional<TrackedTransform> latest(const StreamId& id) const;
  std::optional<StreamState> stream(const StreamId& id) const;
  std::vector<StreamState> streams() const;  // ordered by device/sensor
  std::map<std::string, device_status_t> device_statuses() const;

  // Ends the dispatch thread; idempotent, prompt even when no message arrives.
  void stop();

 private:
  struct Impl;
  explicit Subscriber(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace covtrack::client
