// The transform graph and combiners against Monte Carlo on SE(3): every expected value
// here is sampled, never typed in.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <thread>

#include <Eigen/Eigenvalues>

#include "covtrack/client/combiner.hpp"
#include "covtrack/client/graph_osgar_matrix16.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "graph_samples.hpp"

using namespace covtrack;
using namespace covtrack::client;

using namespace covtrack::client::test;

namespace {

// world -> tracker_base -> head (tracked) -> camera, plus object frames 2 m ahead of the
// camera (camera looks along its +z), one attached to world and one to head.
struct HeadWorld {
  const StreamId head_stream{"is900", "head"};
  const Pose T_world_base = pose(0.5, -0.3, 2.5, 0.1, -0.2, 0.3);
  const Pose T_base_head = pose(0.4, 1.2, -1.0, -0.3, 0.5, 0.2);
  const Pose T_head_camera = pose(0.05, 0.02, 0.08, 0.02, -0.1, 0.05);
  const Pose T_camera_object_mean = pose(0.1, -0.2, 2.0, 0.4, 0.1, -0.3);
  const Mat6 C_base = covariance(0.002, 1 * kDeg, 1);
  const Mat6 C_head = covariance(0.005, 3 * kDeg, 2);
  const Mat6 C_camera = covariance(0.001, 0.5 * kDeg, 3);
  const Mat6 C_object = covariance(0.01, 5 * kDeg, 4);
  Pose T_world_camera() const { return T_world_base * T_base_head * T_head_camera; }
  Pose T_world_object() const { return T_world_camera() * T_camera_object_mean; }
  Pose T_head_object() const { return T_head_camera * T_camera_object_mean; }

  TransformGraph graph;
  HeadWorld() {
    EXPECT_TRUE(graph.add_static_edge("world", "tracker_base", T_world_base, C_base));
    EXPECT_TRUE(graph.add_tracked_edge("tracker_base", "head", head_stream));
    EXPECT_TRUE(graph.add_static_edge("head", "camera", T_head_camera, C_camera));
    EXPECT_TRUE(graph.add_static_edge("world", "object", T_world_object(), C_object));
    EXPECT_TRUE(graph.add_static_edge("head", "held_object", T_head_object(), C_object));
    EXPECT_TRUE(graph.update(head_stream, report(head_stream, T_base_head, C_head, kT0)));
  }
};

}  // namespace

TEST(TransformGraph, WorldObjectMatchesMonteCarlo) {
  HeadWorld w;
  auto r = w.graph.query("camera", "object", kT0);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_FALSE(r->unbounded);
  EXPECT_TRUE(r->T.isApprox(w.T_camera_object_mean, 1e-9));
  const Sampler base(w.T_world_base, w.C_base), head(w.T_base_head, w.C_head),
      cam(w.T_head_camera, w.C_camera), obj(w.T_world_object(), w.C_object);
  const Mat6 mc = monte_carlo(r->T, [&](std::mt19937& g) {
    return (base(g) * head(g) * cam(g)).inverse() * obj(g);
  });
  const double err = relative_frobenius(r->covariance, mc);
  std::printf("camera->world object: relative Frobenius error vs Monte Carlo %.4f\n", err);
  EXPECT_LT(err, 0.03);
}

TEST(TransformGraph, HeadAttachedObjectMatchesMonteCarloAndIgnoresSharedEdges) {
  HeadWorld w;
  auto r = w.graph.query("camera", "held_object", kT0);
  ASSERT_TRUE(r) << r.error().message;
  // Sample the whole root paths: the shared edges cancel in reality, not just in algebra.
  const Sampler base(w.T_world_base, w.C_base), head(w.T_base_head, w.C_head),
      cam(w.T_head_camera, w.C_camera), obj(w.T_head_object(), w.C_object);
  const Mat6 mc = monte_carlo(r->T, [&](std::mt19937& g) {
    const Pose b = base(g), h = head(g);
    return (b * h * cam(g)).inverse() * (b * h * obj(g));
  });
  const double err = relative_frobenius(r->covariance, mc);
  std::printf("camera->held object: relative Frobenius error vs Monte Carlo %.4f\n", err);
  EXPECT_LT(err, 0.03);

  // The head tracker's covariance does not enter T_camera_held_object, nor does its LOST.
  ASSERT_TRUE(w.graph.update("head", report(w.head_stream, w.T_base_head, 100 * w.C_head, kT0 + 1)));
  auto r2 = w.graph.query("camera", "held_object", kT0 + 1);
  ASSERT_TRUE(r2);
  EXPECT_LT((r2->covariance - r->covariance).norm(), 1e-12 * r->covariance.norm());
  ASSERT_TRUE(w.graph.update("head", report(w.head_stream, w.T_base_head, w.C_head, kT0 + 2,
                                            TrackingStatus::Lost)));
  auto r3 = w.graph.query("camera", "held_object", kT0 + 2);
  ASSERT_TRUE(r3);
  EXPECT_FALSE(r3->unbounded);
  EXPECT_TRUE(w.graph.query("camera", "object", kT0 + 2)->unbounded);
}

TEST(TransformGraph, OsgarModelsAgreeWithExactWithoutSharedEdges) {
  // With the LCA at the root, root-based propagation is right: the dissertation's
  // 16-element model, converted to BODY, must then equal the exact first-order result (a
  // check of the 16-element implementation and of its conversion).
  HeadWorld w;
  auto exact = w.graph.query("camera", "object", kT0, Propagation::LowestCommonAncestor);
  auto osgar16 = w.graph.query("camera", "object", kT0, Propagation::OsgarMatrix16);
  auto root = w.graph.query("camera", "object", kT0, Propagation::OsgarRoot);
  ASSERT_TRUE(exact && osgar16 && root);
  EXPECT_LT(relative_frobenius(osgar16->covariance, exact->covariance), 1e-9);
  EXPECT_LT(relative_frobenius(root->covariance, exact->covariance), 1e-9);
  EXPECT_TRUE(osgar16->T.isApprox(exact->T, 1e-12));
}

TEST(TransformGraph, OsgarModelsOverestimateHeadAttachedObject) {
  HeadWorld w;
  auto exact = w.graph.query("camera", "held_object", kT0, Propagation::LowestCommonAncestor);
  auto osgar16 = w.graph.query("camera", "held_object", kT0, Propagation::OsgarMatrix16);
  auto root = w.graph.query("camera", "held_object", kT0, Propagation::OsgarRoot);
  ASSERT_TRUE(exact && osgar16 && root);
  auto position_sigma = [](const Mat6& c) { return std::sqrt(c.topLeftCorner<3, 3>().trace()); };
  const double ratio16 = position_sigma(osgar16->covariance) / position_sigma(exact->covariance);
  const double ratio_root = position_sigma(root->covariance) / position_sigma(exact->covariance);
  std::printf("held object position sigma: exact %.2f mm, 16-element root model %.2f mm (x%.1f), "
              "root-based %.2f mm (x%.1f)\n",
              1e3 * position_sigma(exact->covariance), 1e3 * position_sigma(osgar16->covariance),
              ratio16, 1e3 * position_sigma(root->covariance), ratio_root);
  EXPECT_GT(ratio16, 3.0);
  EXPECT_NEAR(ratio16, ratio_root, 1e-6 * ratio_root);  // both are the same first-order flaw
}

TEST(GraphOsgarMatrix16, RoundTripsBodyCovariance) {
  const Pose T = pose(1, 2, 3, 0.3, -0.4, 0.5);
  const Mat6 C = covariance(0.01, 0.02, 9);
  EXPECT_LT(relative_frobenius(body_from_matrix16(T, matrix16_from_body(T, C)), C), 1e-12);
}

TEST(TransformGraph, StaleTrackedEdgeGrowsWithAge) {
  const StreamId id{"vive", "tracker1"};
  const MotionBound motion{0.5, 1.0};
  TransformGraph g;
  ASSERT_TRUE(g.add_tracked_edge("world", "hand", id, motion));
  const Pose T = pose(0.2, 0.3, 1.0, 0.1, 0.2, 0.3);
  const Mat6 C = covariance(0.001, 0.01, 5);
  ASSERT_TRUE(g.update(id, report(id, T, C, kT0)));
  auto fresh = g.query("world", "hand", kT0);
  auto old = g.query("world", "hand", kT0 + 200'000);  // 0.2 s later
  ASSERT_TRUE(fresh && old);
  EXPECT_LT((fresh->covariance - C).norm(), 1e-15);
  const Mat6 growth = old->covariance - fresh->covariance;
  // (v age)^2 / 3 per translation axis, (w age)^2 / 3 per rotation axis.
  EXPECT_NEAR(growth(0, 0), std::pow(0.5 * 0.2, 2) / 3, 1e-12);
  EXPECT_NEAR(growth(4, 4), std::pow(1.0 * 0.2, 2) / 3, 1e-12);
  EXPECT_LT((growth - Mat6(growth.diagonal().asDiagonal())).norm(), 1e-15);
  // A report older than the stored one (out of order) does not replace it.
  ASSERT_TRUE(g.update(id, report(id, pose(9, 9, 9, 0, 0, 0), C, kT0 - 1)));
  EXPECT_TRUE(g.query("world", "hand", kT0)->T.isApprox(T));
  // The inverse direction grows too (through the adjoint): T_hand_world.
  auto inv_old = g.query("hand", "world", kT0 + 200'000);
  ASSERT_TRUE(inv_old);
  const Mat6 Ad = se3_adjoint(T);
  EXPECT_LT(relative_frobenius(inv_old->covariance, Ad * old->covariance * Ad.transpose()), 1e-12);
}

TEST(TransformGraph, LostOrNeverReportedIsUnbounded) {
  const StreamId id{"vive", "tracker1"};
  TransformGraph g;
  ASSERT_TRUE(g.add_tracked_edge("world", "hand", id));
  ASSERT_TRUE(g.add_static_edge("hand", "tool", pose(0, 0, 0.1, 0, 0, 0), covariance(1e-3, 1e-3, 1)));
  auto never = g.query("world", "tool", kT0);
  ASSERT_TRUE(never);
  EXPECT_TRUE(never->unbounded);
  EXPECT_FALSE(g.query("hand", "tool", kT0)->unbounded);  // the tracked edge is not on this path
  Mat6 inf = Mat6::Zero();
  inf.diagonal().setConstant(std::numeric_limits<double>::infinity());
  ASSERT_TRUE(g.update(id, report(id, pose(1, 0, 0, 0, 0, 0), inf, kT0, TrackingStatus::Lost)));
  auto lost = g.query("world", "tool", kT0);
  ASSERT_TRUE(lost);
  EXPECT_TRUE(lost->unbounded);
  EXPECT_TRUE(lost->covariance.allFinite());  // never leaks the infinite matrix
  ASSERT_TRUE(g.update(id, report(id, pose(1, 0, 0, 0, 0, 0), covariance(1e-3, 1e-3, 2), kT0 + 1)));
  EXPECT_FALSE(g.query("world", "tool", kT0 + 1)->unbounded);
}

// A device configured in another parent frame than the scene expects: its reports are
// refused with both frame names, never used as if they were relative to the scene's.
TEST(TransformGraph, AReportInAnotherParentFrameIsRefusedWithBothNames) {
  const StreamId id{"optical", "head"};
  TransformGraph g;
  ASSERT_TRUE(g.add_static_edge("world", "tracker_base", pose(0, 0, 2.2, 0, 0, 0)));
  ASSERT_TRUE(g.add_tracked_edge("tracker_base", "head", id));
  TrackedTransform r = report(id, pose(0, 0.5, 0.6, 0, 0, 0), covariance(1e-3, 1e-3, 3), kT0);
  r.parent_frame = "world";
  const auto mismatch = g.frame_mismatch(r);
  ASSERT_TRUE(mismatch);
  EXPECT_NE(mismatch->find("'world'"), std::string::npos) << *mismatch;
  EXPECT_NE(mismatch->find("'tracker_base'"), std::string::npos) << *mismatch;
  EXPECT_NE(mismatch->find("optical/head"), std::string::npos) << *mismatch;
  const auto refused = g.update(id, r);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, *mismatch);
  EXPECT_TRUE(g.query("world", "head", kT0)->unbounded);  // not stored
  r.parent_frame = "tracker_base";
  EXPECT_FALSE(g.frame_mismatch(r));
  ASSERT_TRUE(g.update(id, r));
  EXPECT_FALSE(g.query("world", "head", kT0)->unbounded);
  r.parent_frame.clear();  // a report that names no frame is taken as it is
  EXPECT_FALSE(g.frame_mismatch(r));
}

TEST(TransformGraph, RejectsCyclesSecondParentsAndUnknownFrames) {
  TransformGraph g;
  ASSERT_TRUE(g.add_static_edge("a", "b", Pose::Identity()));
  ASSERT_TRUE(g.add_static_edge("b", "c", Pose::Identity()));
  auto cycle = g.add_static_edge("c", "a", Pose::Identity());
  ASSERT_FALSE(cycle);
  EXPECT_NE(cycle.error().message.find("cycle"), std::string::npos) << cycle.error().message;
  auto second = g.add_static_edge("x", "c", Pose::Identity());
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("second parent"), std::string::npos) << second.error().message;
  EXPECT_FALSE(g.add_static_edge("d", "d", Pose::Identity()));
  auto unknown = g.query("a", "nowhere", kT0);
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("nowhere"), std::string::npos);
  ASSERT_TRUE(g.add_static_edge("other_root", "e", Pose::Identity()));
  EXPECT_FALSE(g.query("c", "e", kT0));  // different trees
  EXPECT_FALSE(g.update(StreamId{"no", "stream"}, TrackedTransform{}));
  EXPECT_FALSE(g.update("b", TrackedTransform{}));  // a static edge
  EXPECT_FALSE(g.update("nowhere", TrackedTransform{}));
  EXPECT_FALSE(g.add_combined_edge("a", "z", {}, Combiner::smallest()));
}

// The cycle check keeps track of which frames share a tree as trees are joined: a chain
// added in a random order (pieces that grow and merge) takes every link, refuses every
// edge that would close a loop on the way, and gives the same T_f0_fN as the chain added
// top-down.
TEST(TransformGraph, ChainAddedInAnyOrderRefusesEveryLoopAndQueriesAlike) {
  constexpr int kLinks = 300;
  std::vector<int> order(kLinks);
  for (int i = 0; i < kLinks; ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(22));
  const auto name = [](int i) { return "f" + std::to_string(i); };
  const auto link = [&](int i) { return pose(0.01, 0, 0.002 * (i % 7), 0, 0.01, 0.002 * i); };
  TransformGraph in_order, shuffled;
  for (int i = 0; i < kLinks; ++i)
    ASSERT_TRUE(in_order.add_static_edge(name(i), name(i + 1), link(i), covariance(1e-3, 1e-3, i)));
  std::vector<bool> added(kLinks, false);  // link i: f_i -> f_i+1
  int loops_refused = 0;
  for (int i : order) {
    ASSERT_TRUE(shuffled.add_static_edge(name(i), name(i + 1), link(i), covariance(1e-3, 1e-3, i))) << i;
    added[i] = true;
    // The piece holding link i runs from f_top to f_bottom; an edge from any of its frames
    // back to f_top closes a loop.
    int top = i, bottom = i + 1;
    while (top > 0 && added[top - 1]) --top;
    while (bottom < kLinks && added[bottom]) ++bottom;
    auto loop = shuffled.add_static_edge(name(bottom), name(top), Pose::Identity());
    ASSERT_FALSE(loop) << "f" << bottom << " -> f" << top << " closes a loop";
    EXPECT_NE(loop.error().message.find("cycle"), std::string::npos) << loop.error().message;
    ++loops_refused;
  }
  EXPECT_EQ(loops_refused, kLinks);
  const auto a = in_order.query("f0", name(kLinks), kT0);
  const auto b = shuffled.query("f0", name(kLinks), kT0);
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->T.isApprox(b->T, 1e-12));
  EXPECT_TRUE(a->covariance.isApprox(b->covariance, 1e-12));
  EXPECT_GT(a->covariance.trace(), 0);
}

TEST(Combiner, GraphEdgeSwitchesWhenAPathGoesLost) {
  const StreamId vision{"cam", "marker7"}, room{"is900", "wand"};
  TransformGraph g;
  ASSERT_TRUE(g.add_combined_edge("world", "cube", {TrackedSource{vision, {}}, TrackedSource{room, {}}},
                                  Combiner::smallest()));
  const Pose Tv = pose(1, 0, 0, 0, 0, 0), Tr = pose(1.01, 0, 0, 0, 0, 0);
  ASSERT_TRUE(g.update(vision, report(vision, Tv, covariance(0.001, 0.01, 1), kT0)));
  ASSERT_TRUE(g.update(room, report(room, Tr, covariance(0.02, 0.01, 2), kT0)));
  auto both = g.query_detailed("world", "cube", kT0, Propagation::LowestCommonAncestor);
  ASSERT_TRUE(both);
  ASSERT_EQ(both->combiner_choices.size(), 1u);
  EXPECT_EQ(both->combiner_choices[0].chosen, 0u);
  EXPECT_TRUE(both->pose.T.isApprox(Tv));

  // The vision tracker loses the marker: its last pose is kept but never chosen.
  ASSERT_TRUE(g.update(vision, report(vision, Tv, covariance(0.001, 0.01, 1), kT0 + 1, TrackingStatus::Lost)));
  auto fallback = g.query_detailed("world", "cube", kT0 + 1, Propagation::LowestCommonAncestor);
  ASSERT_TRUE(fallback);
  EXPECT_FALSE(fallback->pose.unbounded);
  EXPECT_EQ(fallback->combiner_choices[0].chosen, 1u);
  EXPECT_TRUE(fallback->pose.T.isApprox(Tr));

  ASSERT_TRUE(g.update(room, report(room, Tr, Mat6::Zero(), kT0 + 1, TrackingStatus::Lost)));
  EXPECT_TRUE(g.query("world", "cube", kT0 + 1)->unbounded);
}

TEST(Combiner, CallbackSeesOnlyBoundedCandidatesAndIsChecked) {
  std::vector<UncertainPose> c(3);
  c[0].unbounded = true;
  c[1].covariance = covariance(0.01, 0.01, 1);
  c[2].covariance = covariance(0.001, 0.01, 2);
  std::size_t seen = 0;
  auto last = Combiner::callback([&](std::span<const UncertainPose> b) {
    seen = b.size();
    return Combined{b.back(), b.size() - 1, false};
  });
  auto r = last.combine(c);
  ASSERT_TRUE(r);
  EXPECT_EQ(seen, 2u);
  EXPECT_EQ(r->chosen, 2u);  // mapped back to the caller's indices
  auto bad = Combiner::callback([](std::span<const UncertainPose> b) { return Combined{b[0], 7, false}; });
  EXPECT_FALSE(bad.combine(c));
  EXPECT_FALSE(Combiner::smallest().combine({}));
  EXPECT_EQ(Combiner::smallest(CovarianceSize::TranslationDeterminant).combine(c)->chosen, 2u);
}

namespace {

// Two estimates of T0 sharing a correlated error component: T_i = T0 Exp(-(s + e_i)), so
// each one's declared BODY covariance Cs + Ce_i is right, but they are not independent.
// Returns min eigenvalue of L^-1 (P_declared - E[err err^T]) L^-T, P = L L^T: >= 0 when the
// fusion is consistent (dominates its true error), whatever the units.
double whitened_margin(const std::function<UncertainPose(const UncertainPose&, const UncertainPose&)>& fuse) {
  const Pose T0 = pose(0.3, -0.2, 1.5, 0.2, 0.1, -0.4);
  const Mat6 Cs = covariance(0.008, 2 * kDeg, 11);
  Mat6 Ce1 = Mat6::Zero(), Ce2 = Mat6::Zero();
  Ce1.diagonal() << 1e-5, 1e-6, 1e-6, 1e-4, 1e-6, 1e-6;  // two differently shaped errors
  Ce2.diagonal() << 1e-6, 1e-5, 1e-6, 1e-6, 1e-6, 1e-4;
  const Sampler s(Pose::Identity(), Cs), e1(Pose::Identity(), Ce1), e2(Pose::Identity(), Ce2);
  std::mt19937 rng(7);
  const int n = 20'000;
  Mat6 M = Mat6::Zero(), P = Mat6::Zero();
  for (int i = 0; i < n; ++i) {
    const Vec6 xs = se3_log(s(rng));
    const UncertainPose a{T0 * se3_exp(-(xs + se3_log(e1(rng)))), Cs + Ce1, false};
    const UncertainPose b{T0 * se3_exp(-(xs + se3_log(e2(rng)))), Cs + Ce2, false};
    const UncertainPose f = fuse(a, b);
    const Vec6 err = boxminus(T0, f.T);
    M += err * err.transpose();
    P += f.covariance;
  }
  M /= n;
  P /= n;
  const Eigen::Matrix<double, 6, 6> L = P.llt().matrixL();
  const Mat6 W = L.triangularView<Eigen::Lower>().solve(
      L.triangularView<Eigen::Lower>().solve(P - M).transpose());
  return Eigen::SelfAdjointEigenSolver<Mat6>(0.5 * (W + W.transpose())).eigenvalues().minCoeff();
}

}  // namespace

TEST(Combiner, CovarianceIntersectionIsConsistentOnCorrelatedInputs) {
  const double ci = whitened_margin([](const UncertainPose& a, const UncertainPose& b) {
    return Combiner::covariance_intersection().combine(std::vector{a, b})->pose;
  });
  // Naive fusion, assuming independence: information adds.
  const double naive = whitened_margin([](const UncertainPose& a, const UncertainPose& b) {
    const Vec6 d = boxminus(b.T, a.T);
    const Mat6 Ia = a.covariance.inverse(), Ib = b.covariance.inverse();
    const Mat6 P = (Ia + Ib).inverse();
    return UncertainPose{boxplus(a.T, P * Ib * d), P, false};
  });
  std::printf("whitened min eigenvalue of declared - true covariance: CI %.3f, naive %.3f\n", ci, naive);
  EXPECT_GT(ci, -0.05);     // CI dominates its true error (up to sampling noise)
  EXPECT_LT(naive, -0.3);   // naive fusion claims far too much: the check can fail
}

TEST(Combiner, CovarianceIntersectionOfIdenticalEstimatesIsThatEstimate) {
  const UncertainPose a{pose(1, 2, 3, 0.1, 0.2, 0.3), covariance(0.01, 0.02, 3), false};
  double w = -1;
  const UncertainPose f = covariance_intersection(a, a, &w);
  EXPECT_TRUE(f.T.isApprox(a.T, 1e-12));
  EXPECT_LT(relative_frobenius(f.covariance, a.covariance), 1e-6);
  EXPECT_GE(w, 0.0);
  EXPECT_LE(w, 1.0);
}

TEST(TransformGraph, ConcurrentUpdatesAndQueries) {
  // A writer moves the head along x while a reader queries: every answer must be one of
  // the written states, never a torn mix (run under TSan to check the locking itself).
  HeadWorld w;
  std::atomic<bool> done = false;
  std::thread writer([&] {
    for (int i = 1; i <= 5000; ++i) {
      Pose T = w.T_base_head;
      T.translation().x() += 1e-3 * i;
      (void)w.graph.update(w.head_stream, report(w.head_stream, T, w.C_head * i, kT0 + i));
    }
    done = true;
  });
  int queries = 0;
  while (!done || queries == 0) {
    auto r = w.graph.query("tracker_base", "head", kT0 + 10'000);
    ASSERT_TRUE(r);
    const double k = std::round((r->T.translation().x() - w.T_base_head.translation().x()) / 1e-3);
    ASSERT_GE(k, 0.0);
    // Covariance k * C_head (plus no staleness: zero motion bound) pairs with pose k.
    const double expected = (k == 0 ? 1.0 : k) * w.C_head(0, 0);
    ASSERT_NEAR(r->covariance(0, 0), expected, 1e-9 * expected);
    ++queries;
  }
  writer.join();
  EXPECT_GT(queries, 0);
}
