#include "covtrack/client/transform_graph.hpp"

#include <algorithm>
#include <atomic>
#include <unordered_set>

#include "covtrack/client/graph_chain.hpp"
#include "covtrack/client/graph_osgar_matrix16.hpp"
#include "graph_fusion.hpp"

namespace covtrack::client {

namespace {
std::uint64_t next_graph_id() {
  static std::atomic<std::uint64_t> last{0};
  return ++last;
}
}  // namespace

TransformGraph::TransformGraph(Propagation mode) : id_(next_graph_id()), mode_(mode) {}

std::optional<TransformGraph::FrameKey> TransformGraph::key(const std::string& frame) const {
  std::lock_guard lock(mutex_);
  const auto index = find(frame);
  if (!index) return std::nullopt;
  return FrameKey{id_, *index};
}

Result<UncertainPose> TransformGraph::query(FrameKey A, FrameKey B, std::int64_t now_us) const {
  std::lock_guard lock(mutex_);
  if (A.graph != id_ || B.graph != id_) return fail("transform graph: a frame key from another graph");
  auto r = query_locked(A.index, B.index, now_us, mode_);
  if (!r) return std::unexpected(r.error());
  return r->pose;
}

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

void TransformGraph::ancestry(FrameIndex frame, std::vector<FrameIndex>& out) const {
  out.assign(1, frame);
  for (auto p = frames_[frame].parent; p; p = frames_[*p].parent) out.push_back(*p);
}

Result<void> TransformGraph::add_edge(const std::string& parent, const std::string& child, Edge edge) {
  std::lock_guard lock(mutex_);
  return link(parent, child, std::move(edge));
}

Result<void> TransformGraph::link(const std::string& parent, const std::string& child, Edge edge) {
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
  return add_edge(parent, child, Edge{{StaticSource{T_parent_child, covariance}}, std::nullopt, {}});
}

Result<void> TransformGraph::add_tracked_edge(const std::string& parent, const std::string& child,
                                              const StreamId& stream, const MotionBound& motion) {
  return add_edge(parent, child, Edge{{TrackedSource{stream, motion}}, std::nullopt, {}});
}

Result<void> TransformGraph::add_combined_edge(const std::string& parent, const std::string& child,
                                               std::vector<EdgeSource> sources, Combiner combiner) {
  if (sources.empty())
    return fail("transform graph: combined edge " + parent + " -> " + child + " has no source");
  return add_edge(parent, child, Edge{std::move(sources), std::move(combiner), {}});
}

Result<void> TransformGraph::add_fused_frame(const std::string& parent, const std::string& child,
                                             std::vector<std::string> via, std::optional<Combiner> combiner) {
  std::lock_guard lock(mutex_);
  const std::string what = "transform graph: fused frame '" + child + "'";
  if (via.empty()) return fail(what + " names no path (via)");
  const auto p = find(parent);
  if (!p) return fail(what + ": unknown parent frame '" + parent + "'");
  Edge edge;
  for (const std::string& name : via) {
    const auto v = find(name);
    if (!v) return fail(what + ": unknown via frame '" + name + "'");
    if (tree_of(*v) != tree_of(*p))
      return fail(what + ": via frame '" + name + "' is not connected to parent '" + parent + "'");
    if (std::find(edge.via.begin(), edge.via.end(), *v) != edge.via.end())
      return fail(what + ": via frame '" + name + "' is named twice");
    edge.via.push_back(*v);
  }
  // The via frames are in the parent's tree, so link()'s cycle check also keeps them out
  // of the child's: a fused edge never depends on itself.
  edge.combiner = std::move(combiner);
  return link(parent, child, std::move(edge));
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

// What one query has evaluated: each edge once, as a value and, where a fused frame made
// it so, as a linear function of other edges' errors (graph_fusion.hpp).
struct TransformGraph::QueryState {
  struct Evaluated {
    UncertainPose value;
    // None: the edge's error is its own (value.covariance), as for every edge of a query
    // that passes no fused frame, which thus never builds a linear form.
    std::optional<fusion::LinearEstimate> linear;
  };
  std::int64_t now_us = 0;
  std::unordered_map<FrameIndex, Evaluated> edges;
  std::vector<EdgeChoice> choices;

  fusion::EdgeCovariance covariance_of() const {
    return [this](fusion::EdgeKey e) -> const Mat6& { return edges.at(e).value.covariance; };
  }
  // T_A_B along the path: the edges from A up, inverted, then down to B.
  fusion::LinearEstimate along(const TreePath& path) const {
    std::vector<fusion::LinearEstimate> own;  // one-term forms of the edges without one
    own.reserve(path.up_A.size() + path.up_B.size());  // the factors point into it
    const auto form = [&](FrameIndex c) -> const fusion::LinearEstimate* {
      const Evaluated& e = edges.at(c);
      if (e.linear) return &*e.linear;
      return &own.emplace_back(fusion::LinearEstimate{e.value.T, {{c, Mat6::Identity()}}});
    };
    std::vector<fusion::LinearFactor> factors;
    for (FrameIndex c : path.up_A) factors.push_back({form(c), true});
    for (auto it = path.up_B.rbegin(); it != path.up_B.rend(); ++it) factors.push_back({form(*it), false});
    return fusion::compose(factors);
  }
};

bool TransformGraph::tree_path(FrameIndex A, FrameIndex B, TreePath& path) const {
  std::vector<FrameIndex>& up_A = path.up_A;
  std::vector<FrameIndex>& up_B = path.up_B;
  ancestry(A, up_A);
  ancestry(B, up_B);
  // The lowest of B's ancestors that is one of A's. A short ancestry (the usual scene) is
  // searched as it is; a hash set would cost more than it saves.
  constexpr std::size_t kShort = 16;
  std::unordered_set<FrameIndex> set_A;
  if (up_A.size() > kShort) set_A.insert(up_A.begin(), up_A.end());
  const auto lca = std::find_if(up_B.begin(), up_B.end(), [&](FrameIndex f) {
    return up_A.size() > kShort ? set_A.contains(f) : std::find(up_A.begin(), up_A.end(), f) != up_A.end();
  });
  if (lca == up_B.end()) return false;
  up_A.erase(std::find(up_A.begin(), up_A.end(), *lca), up_A.end());
  up_B.erase(lca, up_B.end());
  return true;
}

Result<void> TransformGraph::evaluate_edge(FrameIndex child, QueryState& state) const {
  if (state.edges.contains(child)) return {};
  if (!frames_[child].edge.via.empty()) return evaluate_fused(child, state);
  auto v = edge_value(child, state.now_us);
  if (!v) return std::unexpected(v.error());
  if (v->choice) state.choices.push_back(*v->choice);
  state.edges[child] = {v->value, std::nullopt};
  return {};
}

Result<void> TransformGraph::evaluate_fused(FrameIndex child, QueryState& state) const {
  const Frame& frame = frames_[child];
  const std::vector<FrameIndex>& via = frame.edge.via;
  std::vector<fusion::LinearEstimate> paths;
  std::vector<UncertainPose> candidates;
  for (FrameIndex v : via) {
    TreePath path;
    tree_path(*frame.parent, v, path);  // one tree: checked when added
    bool unbounded = false;
    for (const auto* part : {&path.up_A, &path.up_B})
      for (FrameIndex c : *part) {
        if (auto r = evaluate_edge(c, state); !r) return r;
        unbounded = unbounded || state.edges.at(c).value.unbounded;
      }
    paths.push_back(state.along(path));
    candidates.push_back({paths.back().T, fusion::covariance(paths.back(), state.covariance_of()), unbounded});
  }

  QueryState::Evaluated out;
  EdgeChoice choice{frame.name, 0, false};
  if (frame.edge.combiner) {
    auto combined = frame.edge.combiner->combine(candidates);
    if (!combined) return fail("transform graph: fused frame '" + frame.name + "': " + combined.error().message);
    choice = {frame.name, combined->chosen, combined->fused};
    out.value = combined->pose;
    // A fusion the combiner made has an unknown correlation with the other edges: its
    // error counts as its own (no linear form).
    if (!combined->fused) out.linear = paths[combined->chosen];
  } else {
    std::vector<fusion::LinearEstimate> bounded;
    std::vector<std::size_t> index_of;
    for (std::size_t k = 0; k < paths.size(); ++k)
      if (!candidates[k].unbounded) {
        bounded.push_back(std::move(paths[k]));
        index_of.push_back(k);
      }
    if (bounded.empty()) {
      out.value = {candidates.front().T, Mat6::Zero(), true};
      out.linear = fusion::LinearEstimate{candidates.front().T, {}};
    } else {
      std::size_t base = 0;
      out.linear = fusion::fuse(bounded, state.covariance_of(), &base);
      const Mat6 c = fusion::covariance(*out.linear, state.covariance_of());
      out.value = {out.linear->T, 0.5 * (c + c.transpose()), false};
      choice = {frame.name, index_of[base], bounded.size() > 1};
    }
  }
  state.choices.push_back(choice);
  state.edges[child] = std::move(out);
  return {};
}

Result<QueryResult> TransformGraph::query_detailed(const std::string& A, const std::string& B,
                                                   std::int64_t now_us, Propagation mode) const {
  std::lock_guard lock(mutex_);  // one lock for the whole query: consistent edges
  const auto a = find(A);
  if (!a) return fail("transform graph: unknown frame '" + A + "'");
  const auto b = find(B);
  if (!b) return fail("transform graph: unknown frame '" + B + "'");
  return query_locked(*a, *b, now_us, mode);
}

Result<QueryResult> TransformGraph::query_locked(FrameIndex a, FrameIndex b, std::int64_t now_us,
                                                 Propagation mode) const {
  TreePath& path = buffers_.path;
  if (!tree_path(a, b, path))
    return fail("transform graph: frames '" + frames_[a].name + "' and '" + frames_[b].name +
                "' are in different trees");
  if (mode != Propagation::LowestCommonAncestor) {  // both whole root paths
    ancestry(a, path.up_A);
    ancestry(b, path.up_B);
    path.up_A.pop_back();
    path.up_B.pop_back();
  }
  const std::vector<FrameIndex>& path_A = path.up_A;  // child frames, A upwards
  const std::vector<FrameIndex>& path_B = path.up_B;

  // The usual query passes no fused frame: every edge on it is its own error and is met
  // once, so its value goes straight into the chain, without the map of evaluated edges a
  // fused frame's paths need (ArView makes one query per object and frame).
  const auto fused = [&](FrameIndex c) { return !frames_[c].edge.via.empty(); };
  if (mode == Propagation::LowestCommonAncestor && std::none_of(path_A.begin(), path_A.end(), fused) &&
      std::none_of(path_B.begin(), path_B.end(), fused)) {
    QueryResult out;
    std::vector<ChainFactor>& factors = buffers_.factors;
    factors.resize(path_A.size() + path_B.size());
    // Evaluated A upwards, then B upwards (the order of the combiner choices); chained from
    // A up to the LCA and down to B.
    for (std::size_t k = 0; k < factors.size(); ++k) {
      const bool up = k < path_A.size();
      const FrameIndex child = up ? path_A[k] : path_B[k - path_A.size()];
      ChainFactor& factor = factors[up ? k : factors.size() - 1 - (k - path_A.size())];
      // An edge of one source (no combiner) is that source's value: read into its factor
      // without edge_value's wrapping (a copy and a result per edge).
      if (const Edge& edge = frames_[child].edge; !edge.combiner) {
        const UncertainPose v = source_value(edge.sources.front(), now_us);
        out.pose.unbounded = out.pose.unbounded || v.unbounded;
        factor = {v.T, v.covariance, up};
        continue;
      }
      auto v = edge_value(child, now_us);
      if (!v) return std::unexpected(v.error());
      if (v->choice) out.combiner_choices.push_back(*v->choice);
      out.pose.unbounded = out.pose.unbounded || v->value.unbounded;
      factor = {v->value.T, v->value.covariance, up};
    }
    const UncertainPose p = compose_chain(factors);
    out.pose.T = p.T;
    out.pose.covariance = p.covariance;
    if (out.pose.unbounded) out.pose.covariance.setZero();
    return out;
  }

  QueryResult out;
  QueryState state;
  state.now_us = now_us;
  for (const auto* part : {&path_A, &path_B})
    for (const auto& child : *part) {
      if (auto r = evaluate_edge(child, state); !r) return std::unexpected(r.error());
      out.pose.unbounded = out.pose.unbounded || state.edges.at(child).value.unbounded;
    }
  out.combiner_choices = std::move(state.choices);
  auto value = [&](FrameIndex c) -> const UncertainPose& { return state.edges.at(c).value; };

  // Root-to-frame chains (top-down) for the root-based comparison modes, which take every
  // edge, fused ones too, as independent.
  auto root_chain = [&](const std::vector<FrameIndex>& path) {
    std::vector<ChainFactor> f;
    for (auto it = path.rbegin(); it != path.rend(); ++it)
      f.push_back({value(*it).T, value(*it).covariance, false});
    return f;
  };

  switch (mode) {
    case Propagation::LowestCommonAncestor: {  // through a fused frame (the rest is above)
      // Its paths may share edges with this one.
      const fusion::LinearEstimate l = state.along(path);
      const Mat6 c = fusion::covariance(l, state.covariance_of());
      out.pose.T = l.T;
      out.pose.covariance = 0.5 * (c + c.transpose());
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
