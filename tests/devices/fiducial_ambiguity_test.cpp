// Small tags seen nearly face-on: the two poses that fit their corners are hard to tell
// apart. A pose reported OK must have its truth inside its 99% region (at most 1% may
// not: the bar, judged as a rate: see below) and must never be a flip, and a pose
// flagged ambiguous must have a covariance that covers both solutions and its truth (the
// same 1%). Views come from the held-out rasteriser and the corner model's camera
// population, so the flip test is judged with the systematic corner terms in play.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "covtrack/emulators/fiducial/noise_calibration.hpp"
#include "fiducial_scene.hpp"
#include "support/one_percent_bar.hpp"
#include "tag_pose.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;

using test::most_outside_at_one_percent;

TEST(FiducialAmbiguity, OkPosesHoldTheirTruthAndAmbiguousOnesCoverBothSolutions) {
  constexpr double kChi2_6_99 = 16.812;
  // A flip (the other solution, tens of degrees away) lies far beyond this; an honest
  // tail draw (chi-square(6) above 100: 1e-19) never does.
  constexpr double kFlip = 100;
  const CornerNoiseModel model;  // the shipped defaults
  DetectorOptions o;
  o.decimate = 1;
  constexpr int kViews = 24;
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(-1, 1);
  int detected = 0, ok = 0, ok_outside = 0, ambiguous = 0, ambiguous_outside = 0;
  int plain_outside = 0;  // the same draws without the inflation
  double max_second_distance = 0, max_ok_nees = 0, ambiguous_nees = 0;
  for (int view = 0; view < kViews; ++view) {
    CalibrationView v;
    v.camera = test::camera(640, 480, 62);
    v.formation = test::random_formation(rng, Rasteriser::JitteredPoints);
    // 0.05-0.07 m at 0.6-0.9 m: 35-75 px across, turned by at most 5 degrees.
    v.tag = {view, 0.06 + 0.01 * u(rng),
             test::tag_pose(0.75 + 0.15 * u(rng), 5 * u(rng), 5 * u(rng), 180 * u(rng), 0.05 * u(rng),
                            0.04 * u(rng))};
    auto draws = draw_view(o, v, 25, 100 + static_cast<std::uint64_t>(view));
    ASSERT_TRUE(draws.has_value()) << draws.error().message;
    for (const ViewDraw& d : *draws) {
      if (!d.detection) continue;
      ++detected;
      const CornerNoise noise = corner_noise(model, d);
      auto pose = estimate_tag_pose(v.camera, d.detection->corners_px, v.tag.size_m, noise);
      ASSERT_TRUE(pose.has_value()) << pose.error().message;
      const Vec6 e = boxminus(d.T_camera_tag_true, pose->best.T_camera_tag);
      const double nees = e.dot(pose->covariance.ldlt().solve(e));
      const bool outside = nees > kChi2_6_99;
      auto plain = estimate_tag_pose(v.camera, d.detection->corners_px, v.tag.size_m, noise, 0.0);
      ASSERT_TRUE(plain.has_value());
      plain_outside += e.dot(plain->covariance.ldlt().solve(e)) > kChi2_6_99;
      if (pose->ambiguous) {
        ++ambiguous, ambiguous_outside += outside, ambiguous_nees += nees;
        const Vec6 s = boxminus(pose->second->T_camera_tag, pose->best.T_camera_tag);
        max_second_distance = std::max(max_second_distance, s.dot(pose->covariance.ldlt().solve(s)));
      } else {
        ++ok, ok_outside += outside;
        max_ok_nees = std::max(max_ok_nees, nees);
      }
    }
  }
  std::printf("detected %d: OK %d (truth outside the 99%% region: %d, at most %d; largest NEES %.1f), ambiguous %d "
              "(outside: %d, at most %d; mean NEES %.2f); without inflation %d outside; largest Mahalanobis^2 of a "
              "second pose %.2f\n",
              detected, ok, ok_outside, most_outside_at_one_percent(ok), max_ok_nees, ambiguous, ambiguous_outside,
              most_outside_at_one_percent(ambiguous), ambiguous ? ambiguous_nees / ambiguous : 0.0, plain_outside,
              max_second_distance);
  EXPECT_GE(detected, kViews * 25 * 9 / 10);
  EXPECT_GE(ambiguous, detected / 4) << "small face-on tags must often be flagged ambiguous";
  EXPECT_LT(max_second_distance, kChi2_6_99) << "the second pose must lie inside the covariance";
  // The bar: of the poses reported OK, at most 1% with the truth outside (as a
  // rate), and none of them a flip.
  EXPECT_LE(ok_outside, most_outside_at_one_percent(ok)) << "OK poses whose truth lies outside their 99% region";
  EXPECT_LT(max_ok_nees, kFlip) << "an OK pose is the other solution";
  // A DEGRADED pose's covariance covers both solutions and the second one's own
  // uncertainty: its truth is held to the same 1% (before the second's uncertainty was
  // added, 56 of 444 were outside).
  EXPECT_LE(ambiguous_outside, most_outside_at_one_percent(ambiguous)) << "ambiguous poses whose truth lies outside";
  EXPECT_LT(ok_outside + ambiguous_outside, plain_outside) << "the inflation must help";
}
