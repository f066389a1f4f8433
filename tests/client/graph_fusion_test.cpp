// Fused frames: one object estimated along two paths of the graph that share an edge.
// Every check is against sampled ground truth (NEES), never a typed-in covariance.
#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "covtrack/client/combiner.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "graph_samples.hpp"

using namespace covtrack;
using namespace covtrack::client;
using namespace covtrack::client::test;

namespace {

// The dissertation's scene: an object held by a room tracker's wand and carrying a marker
// that a head-worn camera sees. Both paths start with the room tracker's registration to
// the world (world -> room), so their errors are correlated through it.
//   world -> room -> wand -> object_by_room
//   world -> room -> head -> camera -> marker -> object_by_camera
struct TwoPaths {
  struct EdgeSpec {
    std::string parent, child;
    Pose T_true;
    Mat6 C;
    std::optional<StreamId> stream;  // tracked, else static
  };
  std::vector<EdgeSpec> edges;
  Pose T_world_object;

  TwoPaths() {
    const StreamId wand{"room", "wand"}, head{"room", "head"}, marker{"camera", "marker"};
    const Pose room = pose(1.0, 0.5, 2.4, 0.05, -0.1, 0.3), to_wand = pose(0.3, -0.4, -1.1, 0.4, 0.2, -0.3),
               to_head = pose(-0.2, 0.6, -0.8, -0.2, 0.3, 0.1), to_camera = pose(0.05, 0.02, 0.08, 0.02, -0.1, 0.05),
               to_marker = pose(0.1, -0.1, 1.2, 0.3, -0.2, 0.4);
    T_world_object = room * to_wand * pose(0.02, 0.01, 0.1, 0.1, 0.0, -0.2);
    const Pose world_marker = room * to_head * to_camera * to_marker;
    edges = {
        // The shared edge dominates, so that ignoring the correlation shows.
        {"world", "room", room, covariance(0.006, 1.0 * kDeg, 31), std::nullopt},
        {"room", "wand", to_wand, covariance(0.002, 0.4 * kDeg, 32), wand},
        {"wand", "object_by_room", to_wand.inverse() * room.inverse() * T_world_object,
         covariance(0.001, 0.2 * kDeg, 33), std::nullopt},
        {"room", "head", to_head, covariance(0.002, 0.5 * kDeg, 34), head},
        {"head", "camera", to_camera, covariance(0.001, 0.2 * kDeg, 35), std::nullopt},
        {"camera", "marker", to_marker, covariance(0.003, 0.8 * kDeg, 36), marker},
        {"marker", "object_by_camera", world_marker.inverse() * T_world_object,
         covariance(0.0005, 0.1 * kDeg, 37), std::nullopt},
    };
  }

  // The graph of one draw: every edge measured as truth (-) its error, so that
  // truth = measurement Exp(xi) with xi ~ N(0, C) exactly as each edge declares.
  void measure(TransformGraph& g, std::mt19937& rng, std::optional<Combiner> combiner = std::nullopt,
               const std::string& lost_stream = "") const {
    for (const auto& e : edges) {
      const Pose T = e.T_true * se3_exp(-se3_log(Sampler(Pose::Identity(), e.C)(rng)));
      if (!e.stream) {
        EXPECT_TRUE(g.add_static_edge(e.parent, e.child, T, e.C));
        continue;
      }
      EXPECT_TRUE(g.add_tracked_edge(e.parent, e.child, *e.stream));
      const auto status = e.stream->key() == lost_stream ? TrackingStatus::Lost : TrackingStatus::Ok;
      EXPECT_TRUE(g.update(*e.stream, report(*e.stream, T, e.C, kT0, status)));
    }
    EXPECT_TRUE(g.add_fused_frame("world", "object", {"object_by_room", "object_by_camera"}, combiner));
  }

  Pose truth(const std::string& frame) const {
    Pose T = Pose::Identity();
    for (std::string f = frame; f != "world";)
      for (const auto& e : edges)
        if (e.child == f) {
          T = e.T_true * T;
          f = e.parent;
        }
    return T;
  }
};

// Mean NEES of query(A, "object") over draws, and the mean covariance trace.
struct Nees {
  double mean = 0, trace = 0;
};
Nees object_nees(const TwoPaths& scene, const std::string& A, std::optional<Combiner> combiner,
                 int draws = 3000) {
  std::mt19937 rng(2026);
  const Pose truth = scene.truth(A).inverse() * scene.T_world_object;
  Nees out;
  for (int i = 0; i < draws; ++i) {
    TransformGraph g;
    scene.measure(g, rng, combiner);
    const auto r = g.query(A, "object", kT0);
    EXPECT_TRUE(r && !r->unbounded);
    const Vec6 e = boxminus(truth, r->T);
    out.mean += e.dot(r->covariance.ldlt().solve(e));
    out.trace += r->covariance.trace();
  }
  out.mean /= draws;
  out.trace /= draws;
  return out;
}

// 99% interval of the mean of 3000 chi-square(6) draws (sd sqrt(12/3000) = 0.063), widened
// by 0.1 for the first-order error of degree-sized rotations.
constexpr double kNeesLow = 5.74, kNeesHigh = 6.26;

}  // namespace

TEST(FusedFrame, JointFusionOfCorrelatedPathsMatchesGroundTruth) {
  const TwoPaths scene;
  const Nees joint = object_nees(scene, "world", std::nullopt);
  // Each path alone, for scale.
  const Nees by_room = object_nees(scene, "world", Combiner::callback([](auto b) { return Combined{b[0], 0, false}; }));
  std::printf("world->object: joint NEES %.3f (trace %.3g), room path alone trace %.3g\n", joint.mean,
              joint.trace, by_room.trace);
  EXPECT_GT(joint.mean, kNeesLow);
  EXPECT_LT(joint.mean, kNeesHigh);
  EXPECT_LT(joint.trace, by_room.trace);  // the second path adds information
}

TEST(FusedFrame, IgnoringTheSharedEdgeIsOverconfidentAndIntersectionIsConservative) {
  const TwoPaths scene;
  // Information adds, as if the paths were independent: what the joint fusion avoids.
  const auto independent = Combiner::callback([](std::span<const UncertainPose> b) {
    if (b.size() < 2) return Combined{b[0], 0, false};
    const Vec6 d = boxminus(b[1].T, b[0].T);
    const Mat6 I0 = b[0].covariance.inverse(), I1 = b[1].covariance.inverse();
    const Mat6 P = (I0 + I1).inverse();
    return Combined{{boxplus(b[0].T, P * I1 * d), P, false}, 0, true};
  });
  const Nees naive = object_nees(scene, "world", independent);
  const Nees ci = object_nees(scene, "world", Combiner::covariance_intersection());
  const Nees joint = object_nees(scene, "world", std::nullopt);
  std::printf("world->object: paths taken as independent NEES %.3f, covariance intersection %.3f "
              "(trace %.3g against the joint fusion's %.3g)\n", naive.mean, ci.mean, ci.trace, joint.trace);
  EXPECT_GT(naive.mean, kNeesHigh + 1.0);
  // Intersection never claims more than it knows, and knowing the correlation beats it.
  EXPECT_LT(ci.mean, kNeesHigh);
  EXPECT_GT(ci.trace, joint.trace);
}

TEST(FusedFrame, AQueryBackThroughTheSharedEdgesKeepsTheCorrelation) {
  // camera -> head -> room -> world -> object: the query walks the edges the fused frame's
  // camera path used, and the room registration both paths used.
  const TwoPaths scene;
  const Nees through = object_nees(scene, "camera", std::nullopt);
  std::printf("camera->object through the fused frame: NEES %.3f\n", through.mean);
  EXPECT_GT(through.mean, kNeesLow);
  EXPECT_LT(through.mean, kNeesHigh);
}

TEST(FusedFrame, IndependentPathsGiveTheInformationSum) {
  const Pose T = pose(0.4, -0.1, 1.3, 0.2, -0.3, 0.1);
  const Mat6 Ca = covariance(0.004, 1 * kDeg, 41), Cb = covariance(0.002, 2 * kDeg, 42);
  TransformGraph g;
  ASSERT_TRUE(g.add_static_edge("world", "a", T, Ca));
  ASSERT_TRUE(g.add_static_edge("world", "b", T, Cb));
  ASSERT_TRUE(g.add_fused_frame("world", "object", {"a", "b"}));
  const auto r = g.query_detailed("world", "object", kT0, Propagation::LowestCommonAncestor);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->pose.T.isApprox(T, 1e-12));
  const Mat6 expected = (Ca.inverse() + Cb.inverse()).inverse();
  EXPECT_LT(relative_frobenius(r->pose.covariance, expected), 1e-9);
  ASSERT_EQ(r->combiner_choices.size(), 1u);
  EXPECT_EQ(r->combiner_choices[0].child_frame, "object");
  EXPECT_TRUE(r->combiner_choices[0].fused);
}

TEST(FusedFrame, APathThatGoesLostLeavesTheOther) {
  const TwoPaths scene;
  std::mt19937 rng(5);
  TransformGraph g;
  scene.measure(g, rng, std::nullopt, "camera/marker");
  const auto fused = g.query_detailed("world", "object", kT0, Propagation::LowestCommonAncestor);
  const auto room_path = g.query("world", "object_by_room", kT0);
  ASSERT_TRUE(fused && room_path);
  EXPECT_FALSE(fused->pose.unbounded);
  EXPECT_TRUE(fused->pose.T.isApprox(room_path->T, 1e-12));
  EXPECT_LT(relative_frobenius(fused->pose.covariance, room_path->covariance), 1e-12);
  ASSERT_EQ(fused->combiner_choices.back().child_frame, "object");
  EXPECT_EQ(fused->combiner_choices.back().chosen, 0u);
  EXPECT_FALSE(fused->combiner_choices.back().fused);

  // Both paths lost: nothing is known.
  TransformGraph both;
  const StreamId a{"room", "a"}, b{"room", "b"};
  ASSERT_TRUE(both.add_tracked_edge("world", "via_a", a));
  ASSERT_TRUE(both.add_tracked_edge("world", "via_b", b));
  ASSERT_TRUE(both.add_fused_frame("world", "object", {"via_a", "via_b"}));
  ASSERT_TRUE(both.update(a, report(a, Pose::Identity(), Mat6::Identity(), kT0, TrackingStatus::Lost)));
  const auto none = both.query("world", "object", kT0);
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->unbounded);
}

TEST(FusedFrame, RefusesWhatCannotBeEvaluated) {
  TransformGraph g;
  ASSERT_TRUE(g.add_static_edge("world", "a", Pose::Identity()));
  ASSERT_TRUE(g.add_static_edge("world", "b", Pose::Identity()));
  ASSERT_TRUE(g.add_static_edge("elsewhere", "c", Pose::Identity()));
  const auto message = [&](const std::string& parent, const std::string& child, std::vector<std::string> via) {
    const auto r = g.add_fused_frame(parent, child, std::move(via));
    return r ? std::string("accepted") : r.error().message;
  };
  EXPECT_NE(message("world", "o", {}).find("names no path"), std::string::npos);
  EXPECT_NE(message("nowhere", "o", {"a"}).find("unknown parent frame 'nowhere'"), std::string::npos);
  EXPECT_NE(message("world", "o", {"a", "z"}).find("unknown via frame 'z'"), std::string::npos);
  EXPECT_NE(message("world", "o", {"a", "c"}).find("'c' is not connected"), std::string::npos);
  EXPECT_NE(message("world", "o", {"a", "a"}).find("named twice"), std::string::npos);
  EXPECT_NE(message("world", "b", {"a"}).find("already has parent"), std::string::npos);
  // A root whose tree holds a via frame would make the fused edge depend on itself.
  ASSERT_TRUE(g.add_static_edge("o_root", "d", Pose::Identity()));
  EXPECT_NE(message("d", "o_root", {"d"}).find("cycle"), std::string::npos);
  EXPECT_EQ(message("world", "o", {"a", "b"}), "accepted");
  EXPECT_FALSE(g.update("o", TrackedTransform{}));  // not a tracked edge
}
