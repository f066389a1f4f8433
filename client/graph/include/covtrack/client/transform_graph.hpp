#pragma once
// A tree of frames whose edges are uncertain transforms T_parent_child: static ones, ones
// tracked by a covtrack stream, and combined ones (several sources of the same transform,
// one combiner). query(A, B, now) gives T_A_B with its BODY covariance.
//
// Propagation: through the lowest common ancestor (LCA) of A and B with exact first-order
// SE(3) Jacobians (graph_chain.hpp), so edges above the LCA, shared by both paths, never
// enter. The root-based models of the osgAR dissertation (docs/background.md) stay
// available for comparison only (Propagation::OsgarRoot, Propagation::OsgarMatrix16).
//
// Edges are independent of each other. A tracked edge's covariance grows with the age of
// its last report (graph_staleness.hpp); a LOST or never reported edge on the path makes
// the result unbounded.
//
// Fused frames: one physical frame estimated along several paths (a marker seen by a
// camera and a room tracker's sensor on the same object) is declared once per path, as
// ordinary frames, plus a fused frame whose edge from a common parent combines the paths
// (add_fused_frame). Paths that share edges are correlated; the graph knows through which
// edges and fuses them by generalised least squares with that exact first-order
// correlation (graph_fusion.hpp), and keeps it when a query passes through the fused
// frame and through those shared edges again.
//
// Thread safety: every method may be called from any thread (one mutex). A query reads all
// edges under one lock, so it never mixes two versions of the graph. Combiner callbacks run
// under that lock: they must not call the graph.
//
// Cost: adding an edge and updating a stream take about constant time whatever the
// graph's size (hash look-ups; a union-find for the cycle check); a query takes time
// linear in the length of its path. A scene of a
// 100,000-link chain loads and is queried end to end in well under a second
// (tests/tools/bench_scene_chain.cpp).
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <variant>
#include <vector>

#include "covtrack/client/combiner.hpp"
#include "covtrack/client/graph_chain.hpp"
#include "covtrack/client/graph_staleness.hpp"
#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/client/uncertain_pose.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

enum class Propagation {
  LowestCommonAncestor,  // exact first-order Jacobians through the LCA (use this)
  OsgarRoot,              // exact Jacobians, but A and B each from the root, taken as
                         // independent: the dissertation's section 4.9.1 flaw, isolated
  OsgarMatrix16,          // the dissertation's additive 16-element matrix model (appendix B,
                         // eq. 29), from the root, converted to 6x6 BODY
                         // (graph_osgar_matrix16.hpp)
};

struct StaticSource {
  Pose T_parent_child = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // BODY
};

struct TrackedSource {
  StreamId stream;
  MotionBound motion;  // how fast the child may move relative to the parent
};

using EdgeSource = std::variant<StaticSource, TrackedSource>;

// Which source a combined edge, or which path a fused frame, used, for the caller to see.
struct EdgeChoice {
  std::string child_frame;  // names the edge
  std::size_t chosen = 0;   // index into the edge's sources or the fused frame's paths; for
                            // a fusion, the one it was linearised at
  bool fused = false;
};

struct QueryResult {
  UncertainPose pose;
  // One per combined edge or fused frame the query used (also those inside a fused frame's
  // paths), in the order they were evaluated.
  std::vector<EdgeChoice> combiner_choices;
};

class TransformGraph {
 public:
  explicit TransformGraph(Propagation mode = Propagation::LowestCommonAncestor);

  // Each adds the edge parent -> child, creating frames as needed. Fails if `child`
  // already has a parent or if the edge would close a cycle (or parent == child).
  Result<void> add_static_edge(const std::string& parent, const std::string& child,
                               const Pose& T_parent_child, const Mat6& covariance = Mat6::Zero());
  Result<void> add_tracked_edge(const std::string& parent, const std::string& child,
                                const StreamId& stream, const MotionBound& motion = {});
  // Fails on an empty source list.
  Result<void> add_combined_edge(const std::string& parent, const std::string& child,
                                 std::vector<EdgeSource> sources, Combiner combiner);
  // Adds `child` with the edge parent -> child estimated along several paths: T_parent_via
  // for each frame in `via`, each of which stands for the same physical frame as `child`
  // reached another way through the graph. `parent` and every via frame must exist and be
  // in one tree; `child` is new, or a root whose tree holds none of them. Paths that
  // report LOST are left out; with none left the edge is unbounded.
  // The fusion is the best estimate of T_parent_child. A query from another frame gets the
  // right covariance through it, but not always a smaller one than a single path would
  // give there: fuse relative to the frame the pose is needed in (the camera, to draw).
  // Without a combiner the paths are fused jointly with their exact correlation (shared
  // edges counted once). A combiner instead sees each path's estimate alone (smallest
  // covariance; covariance intersection, which needs no correlation; a callback); a result
  // it fuses itself counts as independent of every other edge.
  Result<void> add_fused_frame(const std::string& parent, const std::string& child,
                               std::vector<std::string> via,
                               std::optional<Combiner> combiner = std::nullopt);

  // Stores the latest report of a stream (for every edge bound to it). A report measured
  // before the stored one is ignored (out-of-order delivery). Fails if no edge is bound to
  // the stream, or if the report is in another parent frame than the edge's (see
  // frame_mismatch): such a report is not stored. Ready for Subscriber::on_pose:
  // [&](auto& t) { (void)graph.update(t.stream, t); }
  Result<void> update(const StreamId& stream, const TrackedTransform& report);
  // Why a report of a bound stream cannot be used: it gives its pose relative to another
  // frame than the one the graph attaches it to (a device configured with another
  // parent_frame than the scene expects). Both names are in the message. Nothing when it
  // fits, when the report names no parent frame, or when no edge is bound to the stream.
  std::optional<std::string> frame_mismatch(const TrackedTransform& report) const;
  // The same for the tracked edge whose child frame is `edge_child_frame`; fails for an
  // unknown frame, a static edge or a combined edge (update those by stream).
  Result<void> update(const std::string& edge_child_frame, const TrackedTransform& report);

  // T_A_B and its BODY covariance at time now_us (the graph's propagation mode, or the
  // given one). Fails for an unknown frame or frames in different trees.
  Result<UncertainPose> query(const std::string& A, const std::string& B, std::int64_t now_us) const;
  Result<UncertainPose> query(const std::string& A, const std::string& B, std::int64_t now_us,
                              Propagation mode) const;
  Result<QueryResult> query_detailed(const std::string& A, const std::string& B,
                                     std::int64_t now_us, Propagation mode) const;

  // A frame's name looked up once, for a caller that queries the same frames every frame
  // (ArView: 1,000 objects, two name look-ups each per frame otherwise). Frames are never
  // removed, so a key stays good as long as the graph that gave it.
  struct FrameKey {
    std::uint64_t graph = 0;  // which graph gave it (every graph has its own number)
    std::size_t index = 0;
  };
  std::optional<FrameKey> key(const std::string& frame) const;
  std::uint64_t id() const { return id_; }  // the number its keys carry
  // query(A, B, now_us) by keys, in the graph's propagation mode: the same result. Fails
  // for a key another graph gave.
  Result<UncertainPose> query(FrameKey A, FrameKey B, std::int64_t now_us) const;

  bool has_frame(const std::string& frame) const;
  void set_propagation(Propagation mode);

 private:
  using FrameIndex = std::size_t;  // into frames_
  struct Edge {
    std::vector<EdgeSource> sources;   // none for a fused frame
    std::optional<Combiner> combiner;  // set when there are several sources, or for a fused
                                       // frame that does not fuse jointly
    std::vector<FrameIndex> via;       // a fused frame: the frames its paths lead to
  };
  struct Frame {
    std::string name;
    std::optional<FrameIndex> parent;
    Edge edge;  // to the parent; empty for a root
  };
  struct EdgeValue {
    UncertainPose value;
    std::optional<EdgeChoice> choice;
  };
  struct QueryState;  // the edges one query has evaluated (transform_graph.cpp)

  Result<void> add_edge(const std::string& parent, const std::string& child, Edge edge);
  Result<void> link(const std::string& parent, const std::string& child, Edge edge);  // locked
  Result<void> store_report(const StreamId& stream, const TrackedTransform& report);
  std::optional<std::string> mismatch_of(const StreamId& stream, const TrackedTransform& report) const;
  std::optional<FrameIndex> find(const std::string& frame) const;
  FrameIndex add_frame(const std::string& frame);  // a new root
  FrameIndex tree_of(FrameIndex frame);
  void ancestry(FrameIndex frame, std::vector<FrameIndex>& out) const;  // frame, ..., root
  UncertainPose source_value(const EdgeSource& source, std::int64_t now_us) const;
  Result<EdgeValue> edge_value(FrameIndex child, std::int64_t now_us) const;
  // Each evaluates into `state` (once per query) and fails only on a combiner's error.
  Result<void> evaluate_edge(FrameIndex child, QueryState& state) const;
  Result<void> evaluate_fused(FrameIndex child, QueryState& state) const;
  // The child frames of the edges from A up to the LCA and from B up to it.
  struct TreePath {
    std::vector<FrameIndex> up_A, up_B;
  };
  // Into `path`, keeping its memory; false when A and B are in different trees.
  bool tree_path(FrameIndex A, FrameIndex B, TreePath& path) const;
  Result<QueryResult> query_locked(FrameIndex A, FrameIndex B, std::int64_t now_us, Propagation mode) const;

  const std::uint64_t id_;  // FrameKey::graph

  mutable std::mutex mutex_;
  Propagation mode_;
  std::vector<Frame> frames_;
  std::unordered_map<std::string, FrameIndex> index_;  // by name
  // Union-find over frames: two frames are in one tree when their entries lead to the same
  // representative. A cycle check is then one look-up instead of a walk to the root, which
  // made a long chain quadratic to load.
  std::vector<FrameIndex> tree_;
  // StreamId::key() of every stream an edge is bound to -> that edge's parent frame.
  std::unordered_map<std::string, std::string> bound_streams_;
  std::map<std::string, TrackedTransform> latest_;         // by StreamId::key()
  // A query's path and chain, kept from one query to the next (under mutex_): ArView
  // queries every object every frame, and these were its allocations.
  struct QueryBuffers {
    TreePath path;
    std::vector<ChainFactor> factors;
  };
  mutable QueryBuffers buffers_;
};

}  // namespace covtrack::client
