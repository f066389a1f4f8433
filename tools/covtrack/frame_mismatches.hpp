#pragma once
// Streams whose reports the transform graph refuses because the device gives them
// relative to another frame than the scene attaches them to (a config and a scene that
// do not fit together). Each is told once on stderr, with both frame names, and stays
// in the view's legend instead of a silent "no region". Thread-safe: live reports
// arrive on the subscriber's thread.
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/client/transform_graph.hpp"

namespace covtrack::cli {

class FrameMismatches {
 public:
  // `command` prefixes what is told on stderr.
  explicit FrameMismatches(std::string command = "covtrack view") : command_(std::move(command)) {}

  // Feeds the report to the graph (streams the scene does not use are ignored there);
  // a refused one is told on stderr the first time for its stream.
  void update(client::TransformGraph& graph, const client::TrackedTransform& t) {
    if (graph.update(t.stream, t)) return;
    // Refused: only a frame mismatch is worth telling (an unbound stream is just unused).
    const auto mismatch = graph.frame_mismatch(t);
    if (!mismatch) return;
    std::lock_guard lock(mutex_);
    if (reported_parent_.emplace(t.stream.key(), t.parent_frame).second) std::cerr << command_ << ": " << *mismatch << "\n";
  }
  // The frame a refused stream reports in; nothing for a stream that fits.
  std::optional<std::string> reported_parent(const StreamId& id) const {
    std::lock_guard lock(mutex_);
    const auto it = reported_parent_.find(id.key());
    if (it == reported_parent_.end()) return std::nullopt;
    return it->second;
  }

 private:
  std::string command_;
  mutable std::mutex mutex_;
  std::map<std::string, std::string> reported_parent_;  // StreamId::key() -> its parent frame
};

}  // namespace covtrack::cli
