#include "covtrack/client/transform_graph.hpp"

#include <algorithm>
#include <unordered_set>

#include "covtrack/client/graph_chain.hpp"
#include "covtrack/client/graph_osgar_matrix16.hpp"

namespace covtrack::client {

TransformGraph::TransformGraph(Propagation mode) : mode_(mode) {}

void TransformGraph::set_propagation(Propagation mode) {
  std::lock_guard lock(mutex_);
  mode_ = mode;
}

bool TransformGraph::has_frame(const std::string& frame) const {
  std::lock_guard lock(mutex_);
  return index_.contains(frame);
}

std::optional<TransformGraph::FrameIndex> TransformGraph::find(const std::string& frame) const {
  const auto it = index_.find(frame);
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

TransformGraph::FrameIndex TransformGraph::add_frame(const std::string& frame) {
  const FrameIndex index = frames_.size();
  index_.emplace(frame, index);
  frames_.push_back(Frame{frame, std::nullopt, {}});
  tree_.push_back(index);  // a tree of its own
  return index;
}

// The representative of the frame's tree; path halving keeps the way there short.
TransformGraph::FrameIndex TransformGraph::tree_of(FrameIndex frame) {
  while (tree_[frame] != frame) {
    tree_[frame] = tree_[tree_[frame]];
    frame = tree_[frame];
  }
  return frame;
}

std::vector<TransformGraph::FrameIndex> TransformGraph::ancestry(FrameIndex frame) const {
  std::vector<FrameIndex> out{frame};
  for (auto p = frames_[frame].parent; p; p = frames_[*p].parent) out.push_back(*p);
  return out;
}

Result<void> TransformGraph::add_edge(const std::string& parent, const std::string& child, Edge edge) {
  std::lock_guard lock(mutex_);
  if (parent.empty() || child.empty()) return fail("transform graph: empty frame name");
  if (parent == child) return fail("transform graph: edge " + parent + " -> " + child + " is a loop");
  const auto existing_child = find(child), existing_parent = find(parent);
  if (existing_child && frames_[*existing_child].parent)
    return fail("transform graph: frame '" + child + "' already has parent '" +
                frames_[*frames_[*existing_child].parent].name + "'; cannot add a second parent '" + parent +
                "' (use a combined edge for several sources of one transform)");
  // The child has no parent, so it is the root of its tree: the edge closes a cycle exactly
  // when the parent is in that tree.
  if (existing_child && existing_parent && tree_of(*existing_child) == tree_of(*existing_parent))
    return fail("transform graph: edge " + parent + " -> " + child +
                " would close a cycle ('" + child + "' is an ancestor of '" + parent + "')");
  const FrameIndex p = existing_parent ? *existing_parent : add_frame(parent);
  const FrameIndex c = existing_child ? *existing_child : add_frame(child);
  tree_[tree_of(c)] = tree_of(p);
  for (const EdgeSource& source : edge.sources)
    if (const auto* tracked = std::get_if<TrackedSource>(&source))
      bound_streams_.emplace(tracked->stream.key(), parent);
  frames_[c].parent = p;
  frames_[c].edge = std::move(edge);
  return {};
}

Result<void> TransformGraph::add_static_edge(const std::string& parent, const std::string& child,
                                             const Pose& T_parent_child, const Mat6& covariance) {
  return add_edge(parent, child, Edge{{StaticSource{T_parent_child, covariance}}, std::nullopt});
}

Result<void> TransformGraph::add_tracked_edge(const std::string& parent, const std::string& child,
                                              const StreamId& stream, const MotionBound& motion) {
  return add_edge(parent, child, Edge{{TrackedSource{stream, motion}}, std::nullopt});
}

Result<void> TransformGraph::add_combined_edge(const std::string& parent, const std::string& child,
                                               std::vector<EdgeSource> sources, Combiner combiner) {
  if (sources.empty())
    return fail("transform graph: combined edge " + parent + " -> " + child + " has no source");
  return add_edge(parent, child, Edge{std::move(sources), std::move(combiner)});
}

Result<void> TransformGraph::store_report(const StreamId& stream, const TrackedTransform& report) {
  auto [it, inserted] = latest_.try_emplace(stream.key(), report);
  if (!inserted && report.measurement_time_us >= it->second.measurement_time_us) it->second = report;
  return {};
}

Result<void> TransformGraph::update(const StreamId& stream, const TrackedTransform& report) {
  std::lock_guard lock(mutex_);
  if (!bound_streams_.contains(stream.key()))
    return fail("transform graph: no edge is bound to stream " + stream.key());
  if (auto mismatch = mismatch_of(stream, report)) return fail(*mismatch);
  return store_report(stream, report);
}

std::optional<std::string> TransformGraph::frame_mismatch(const TrackedTransform& report) const {
  std::lock_guard lock(mutex_);
  return mismatch_of(report.stream, report);
}

std::optional<std::string> TransformGraph::mismatch_of(const StreamId& stream, const TrackedTransform& report) const {
  const auto it = bound_streams_.find(stream.key());
  if (it == bound_streams_.end() || report.parent_frame.empty() || report.parent_frame == it->second)
    return std::nullopt;
  return "stream " + stream.key() + " reports its pose relative to frame '" + report.parent_frame +
         "', but the graph attaches it to frame '" + it->second +
         "': not used (set the device's parent_frame, or the scene's parent, so that they agree)";
}

Result<void> TransformGraph::update(const std::string& edge_child_frame, const TrackedTransform& report) {
  std::lock_guard lock(mutex_);
  const auto frame = find(edge_child_frame);
  if (!frame) return fail("transform graph: unknown frame '" + edge_child_frame + "'");
  const Edge& edge = frames_[*frame].edge;
  const auto* tracked = edge.sources.size() == 1 ? std::get_if<TrackedSource>(&edge.sources[0]) : nullptr;
  if (!tracked)
    return fail("transform graph: the edge to '" + edge_child_frame +
                "' is not a single tracked edge (update combined edges by stream)");
  return store_report(tracked->stream, report);
}

UncertainPose TransformGraph::source_value(const EdgeSource& source, std::int64_t now_us) const {
  if (const auto* s = std::get_if<StaticSource>(&source)) return {s->T_parent_child, s->covariance, false};
  const auto& tracked = std::get<TrackedSource>(source);
  const auto it = latest_.find(tracked.stream.key());
  UncertainPose out;
  if (it == latest_.end()) {  // never reported: nothing is known
    out.unbounded = true;
    return out;
  }
  const TrackedTransform& r = it->second;
  out.T = r.T_parent_child;  // the last estimate, even when LOST (its covariance is not used)
  if (r.lost()) {
    out.unbounded = true;
    return out;
  }
  out.covariance = r.covariance + staleness_covariance(tracked.motion, r.age_s(now_us));
  return out;
}

Result<TransformGraph::EdgeValue> TransformGraph::edge_value(FrameIndex child, std::int64_t now_us) const {
  const Edge& edge = frames_[child].edge;
  if (!edge.combiner) return EdgeValue{source_value(edge.sources.front(), now_us), std::nullopt};
  std::vector<UncertainPose> candidates;
  for (const auto& s : edge.sources) candidates.push_back(source_value(s, now_us));
  auto combined = edge.combiner->combine(candidates);
  const std::string& name = frames_[child].name;
  if (!combined) return fail("transform graph: edge to '" + name + "': " + combined.error().message);
  return EdgeValue{combined->pose, EdgeChoice{name, combined->chosen, combined->fused}};
}

Result<UncertainPose> TransformGraph::query(const std::string& A, const std::string& B,
                                            std::int64_t now_us) const {
  Propagation mode;
  {
    std::lock_guard lock(mutex_);
    mode = mode_;
  }
  return query(A, B, now_us, mode);
}

Result<UncertainPose> TransformGraph::query(const std::string& A, const std::string& B,
                                            std::int64_t now_us, Propagation mode) const {
  auto r = query_detailed(A, B, now_us, mode);
  if (!r) return std::unexpected(r.error());
  return r->pose;
}

Result<QueryResult> TransformGraph::query_detailed(const std::string& A, const std::string& B,
                                                   std::int64_t now_us, Propagation mode) const {
  std::lock_guard lock(mutex_);  // one lock for the whole query: consistent edges
  for (const auto* f : {&A, &B})
    if (!index_.contains(*f)) return fail("transform graph: unknown frame '" + *f + "'");
  const auto up_A = ancestry(*find(A));
  const auto up_B = ancestry(*find(B));
  const std::unordered_set<FrameIndex> set_A(up_A.begin(), up_A.end());
  const auto lca = std::find_if(up_B.begin(), up_B.end(), [&](FrameIndex f) { return set_A.contains(f); });
  if (lca == up_B.end())
    return fail("transform graph: frames '" + A + "' and '" + B + "' are in different trees");

  // The edges each mode needs: the path through the LCA, or both whole root paths.
  const bool from_root = mode != Propagation::LowestCommonAncestor;
  const auto stop_A = from_root ? up_A.end() - 1 : std::find(up_A.begin(), up_A.end(), *lca);
  const auto stop_B = from_root ? up_B.end() - 1 : lca;
  const std::vector<FrameIndex> path_A(up_A.begin(), stop_A);  // child frames, A upwards
  const std::vector<FrameIndex> path_B(up_B.begin(), stop_B);

  QueryResult out;
  std::unordered_map<FrameIndex, UncertainPose> values;  // each edge evaluated once per query
  for (const auto* path : {&path_A, &path_B})
    for (const auto& child : *path) {
      if (values.contains(child)) continue;
      auto v = edge_value(child, now_us);
      if (!v) return std::unexpected(v.error());
      if (v->choice) out.combiner_choices.push_back(*v->choice);
      out.pose.unbounded = out.pose.unbounded || v->value.unbounded;
      values[child] = v->value;
    }

  // Root-to-frame chains (top-down) for the root-based comparison modes.
  auto root_chain = [&](const std::vector<FrameIndex>& path) {
    std::vector<ChainFactor> f;
    for (auto it = path.rbegin(); it != path.rend(); ++it)
      f.push_back({values[*it].T, values[*it].covariance, false});
    return f;
  };

  switch (mode) {
    case Propagation::LowestCommonAncestor: {
      std::vector<ChainFactor> factors;
      for (const auto& c : path_A) factors.push_back({values[c].T, values[c].covariance, true});
      for (auto it = path_B.rbegin(); it != path_B.rend(); ++it)
        factors.push_back({values[*it].T, values[*it].covariance, false});
      const UncertainPose p = compose_chain(factors);
      out.pose.T = p.T;
      out.pose.covariance = p.covariance;
      break;
    }
    case Propagation::OsgarRoot: {
      const UncertainPose root_A = compose_chain(root_chain(path_A));
      const UncertainPose root_B = compose_chain(root_chain(path_B));
      const std::vector<ChainFactor> f{{root_A.T, root_A.covariance, true},
                                       {root_B.T, root_B.covariance, false}};
      const UncertainPose p = compose_chain(f);
      out.pose.T = p.T;
      out.pose.covariance = p.covariance;
      break;
    }
    case Propagation::OsgarMatrix16: {
      auto estimate = [](const std::vector<ChainFactor>& chain) {
        MatrixEstimate e;
        for (const auto& f : chain) e = osgar_propagate(e, f.T, f.covariance);
        return e;
      };
      const UncertainPose p = osgar_relative(estimate(root_chain(path_A)), estimate(root_chain(path_B)));
      out.pose.T = p.T;
      out.pose.covariance = p.covariance;
      break;
    }
  }
  // An unbounded covariance is meaningless: never hand out numbers that look usable.
  if (out.pose.unbounded) out.pose.covariance.setZero();
  return out;
}

}  // namespace covtrack::client
