// The image-noise input of the corner model: a robust estimate of the sensor's white
// noise from one frame, which edges and smooth shading must not inflate.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "corner_noise.hpp"

using covtrack::fiducial::estimate_image_noise;
using covtrack::fiducial::ring_noise;

namespace {

// A scene with a shading ramp and hard-edged blocks (planar almost everywhere), plus
// Gaussian noise of `sigma` grey levels.
cv::Mat noisy_scene(double sigma, int seed) {
  cv::Mat base(480, 640, CV_32F);
  for (int r = 0; r < base.rows; ++r)
    for (int c = 0; c < base.cols; ++c) base.at<float>(r, c) = 60.0f + 0.15f * c + 0.1f * r;
  for (int k = 0; k < 12; ++k)
    cv::rectangle(base, cv::Rect(20 + 50 * k, 40 + 30 * (k % 5), 30, 60), cv::Scalar(k % 2 ? 20 : 220), cv::FILLED);
  cv::Mat noise(base.size(), CV_32F);
  cv::theRNG().state = static_cast<std::uint64_t>(seed);
  cv::randn(noise, 0.0, sigma);
  cv::Mat out;
  cv::Mat(base + noise).convertTo(out, CV_8U);
  return out;
}

// The same estimator written the plain way (2x2 block sums, store, sort, take the middle),
// as a reference.
double sorted_median_estimate(const cv::Mat& gray) {
  const auto block = [&](int r, int c) {
    return int(gray.at<std::uint8_t>(2 * r, 2 * c)) + gray.at<std::uint8_t>(2 * r, 2 * c + 1) +
           gray.at<std::uint8_t>(2 * r + 1, 2 * c) + gray.at<std::uint8_t>(2 * r + 1, 2 * c + 1);
  };
  std::vector<int> r;
  for (int y = 1; y + 1 < gray.rows / 2; y += 2)
    for (int x = 1; x + 1 < gray.cols / 2; x += 2) {
      const auto p = [&](int dy, int dx) { return block(y + dy, x + dx); };
      r.push_back(std::abs(p(-1, -1) - 2 * p(-1, 0) + p(-1, 1) - 2 * (p(0, -1) - 2 * p(0, 0) + p(0, 1)) +
                           p(1, -1) - 2 * p(1, 0) + p(1, 1)));
    }
  std::sort(r.begin(), r.end());
  return r[r.size() / 2] / (0.6745 * 12.0);
}

// The same filter on single pixels.
double per_pixel_estimate(const cv::Mat& gray) {
  std::vector<int> r;
  for (int y = 1; y + 1 < gray.rows; y += 3)
    for (int x = 1; x + 1 < gray.cols; x += 3) {
      const auto p = [&](int dy, int dx) { return int(gray.at<std::uint8_t>(y + dy, x + dx)); };
      r.push_back(std::abs(p(-1, -1) - 2 * p(-1, 0) + p(-1, 1) - 2 * (p(0, -1) - 2 * p(0, 0) + p(0, 1)) +
                           p(1, -1) - 2 * p(1, 0) + p(1, 1)));
    }
  std::sort(r.begin(), r.end());
  return r[r.size() / 2] / (0.6745 * 6.0);
}

}  // namespace

TEST(ImageNoise, RecoversTheNoiseOfAShadedSceneWithEdges) {
  for (double sigma : {1.0, 3.0, 8.0}) {
    const cv::Mat img = noisy_scene(sigma, 11);
    // Rounding to 8 bits adds 1/12 grey level^2 of its own.
    const double expected = std::sqrt(sigma * sigma + 1.0 / 12);
    EXPECT_NEAR(estimate_image_noise(img), expected, 0.08 * expected) << "sigma " << sigma;
  }
}

TEST(ImageNoise, IsExactlyTheMedianOfTheFilterResponses) {
  for (int seed : {1, 2, 3}) {
    const cv::Mat img = noisy_scene(2.0 + seed, seed);
    EXPECT_DOUBLE_EQ(estimate_image_noise(img), sorted_median_estimate(img)) << "seed " << seed;
  }
  const cv::Mat flat(100, 100, CV_8U, cv::Scalar(128));
  EXPECT_EQ(estimate_image_noise(flat), 0.0);
  EXPECT_EQ(estimate_image_noise(cv::Mat(2, 2, CV_8U, cv::Scalar(0))), 0.0);  // too small to filter
}

// JPEG smooths away most of the finest-scale noise, which a per-pixel filter would read as
// a quieter camera; the noise a few pixels wide, which moves a fitted edge, stays. The
// estimate on 2x2 blocks keeps most of it.
TEST(ImageNoise, SeesThroughJpegCompression) {
  for (int quality : {75, 90}) {
    const double sigma = 4.0;
    const cv::Mat raw = noisy_scene(sigma, 7);
    std::vector<std::uint8_t> bytes;
    cv::imencode(".jpg", raw, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
    const cv::Mat jpeg = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
    // The per-pixel estimate (the same filter on single pixels), for comparison.
    const double per_pixel = per_pixel_estimate(jpeg), blocks = estimate_image_noise(jpeg);
    std::printf("JPEG quality %d, noise %.1f: per-pixel estimate %.2f, 2x2-block estimate %.2f\n", quality, sigma,
                per_pixel, blocks);
    // Measured: at quality 75 the per-pixel filter reads 0.49 for noise 4, the blocks 2.97;
    // at 90, 1.73 and 4.08.
    EXPECT_GT(blocks, 0.7 * sigma) << "quality " << quality;
    EXPECT_LT(blocks, 1.1 * sigma) << "quality " << quality;
    EXPECT_GT(blocks, 2 * per_pixel) << "quality " << quality;
  }
}

namespace {

// A 120 px square with a dark 12 px border on a light page (linear light 0.8 and 0.06),
// turned by `angle_deg` about its centre, with linear-light noise of `sigma` (on the 0-1
// scale), then a tone curve of `gamma` and 8 bits: the way a sensor's noise reaches a
// frame. Returns the image; `corners` gets the square's outer corners.
cv::Mat noisy_tag(double sigma, double gamma, double angle_deg, int seed, std::array<cv::Point2d, 4>& corners) {
  const cv::Point2d centre(320.3, 240.6);
  const double a = angle_deg * M_PI / 180, half = 60, border = 12;
  const cv::Point2d u(std::cos(a), std::sin(a)), v(-std::sin(a), std::cos(a));
  cv::Mat linear(480, 640, CV_32F);
  for (int r = 0; r < linear.rows; ++r)
    for (int c = 0; c < linear.cols; ++c) {
      const cv::Point2d d = cv::Point2d(c, r) - centre;
      const double m = std::max(std::abs(d.dot(u)), std::abs(d.dot(v)));
      linear.at<float>(r, c) = m <= half && m > half - border ? 0.06f : 0.8f;
    }
  cv::GaussianBlur(linear, linear, {0, 0}, 0.8);
  cv::Mat noise(linear.size(), CV_32F);
  cv::theRNG().state = static_cast<std::uint64_t>(seed);
  cv::randn(noise, 0.0, sigma);
  linear = cv::min(cv::max(linear + noise, 0), 1);
  cv::pow(linear, 1 / gamma, linear);
  cv::Mat out;
  linear.convertTo(out, CV_8U, 255);
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {1, 1, -1, -1};
  for (int k = 0; k < 4; ++k) corners[k] = centre + half * (sx[k] * u + sy[k] * v);
  return out;
}

// The noise in the middle of a region of linear level `level`, measured on the pixels.
double true_noise_at(double level, double sigma, double gamma) {
  return 255 * sigma * std::pow(level, 1 / gamma - 1) / gamma;
}

}  // namespace

// Under a tone curve the dark border is noisier than the light page that most of the
// frame shows: the rings inside and outside the edges read their own levels' noise. One
// ring gives about 90 responses, so one estimate scatters by ~12% (more at the page's
// 0.84 grey levels, where a response is a few whole units); the mean of eight draws must
// be within 8% of the truth, each within 40%.
TEST(RingNoise, ReadsTheNoiseAtEachSideOfTheEdge) {
  constexpr int kDraws = 8;
  const std::array<double, 4> width{12, 12, 12, 12};
  for (double angle : {0.0, 17.0, 45.0}) {
    for (double gamma : {1.0, 2.2}) {
      const double sigma = 0.006;
      const double at_border = std::hypot(true_noise_at(0.06, sigma, gamma), std::sqrt(1.0 / 12));
      const double at_page = std::hypot(true_noise_at(0.8, sigma, gamma), std::sqrt(1.0 / 12));
      double inside = 0, outside = 0;
      for (int seed = 1; seed <= kDraws; ++seed) {
        std::array<cv::Point2d, 4> corners;
        const cv::Mat image = noisy_tag(sigma, gamma, angle, seed, corners);
        const double in = ring_noise(image, corners, width, false).sigma, out = ring_noise(image, corners, width, true).sigma;
        EXPECT_GE(ring_noise(image, corners, width, false).responses, 80u);
        EXPECT_NEAR(in, at_border, 0.4 * at_border) << "angle " << angle << " gamma " << gamma << " seed " << seed;
        EXPECT_NEAR(out, at_page, 0.4 * at_page) << "angle " << angle << " gamma " << gamma << " seed " << seed;
        EXPECT_NEAR(estimate_image_noise(image), at_page, 0.1 * at_page) << "angle " << angle << " gamma " << gamma;
        inside += in / kDraws, outside += out / kDraws;
      }
      std::printf("angle %.0f, gamma %.1f: inside %.2f (true %.2f), outside %.2f (true %.2f)\n", angle, gamma, inside,
                  at_border, outside, at_page);
      EXPECT_NEAR(inside, at_border, 0.08 * at_border) << "angle " << angle << " gamma " << gamma;
      EXPECT_NEAR(outside, at_page, 0.08 * at_page) << "angle " << angle << " gamma " << gamma;
    }
  }
}

TEST(RingNoise, NotANumberWhereTheRingIsTooThinOrOffTheImage) {
  std::array<cv::Point2d, 4> corners;
  const cv::Mat image = noisy_tag(0.006, 2.2, 10, 3, corners);
  for (bool outside : {false, true}) {
    EXPECT_TRUE(std::isnan(ring_noise(image, corners, {3, 3, 3, 3}, outside).sigma));
    std::array<cv::Point2d, 4> away = corners;
    for (auto& p : away) p += cv::Point2d(2000, 0);
    EXPECT_TRUE(std::isnan(ring_noise(image, away, {12, 12, 12, 12}, outside).sigma));
    EXPECT_TRUE(std::isnan(ring_noise(image, corners, {NAN, NAN, NAN, NAN}, outside).sigma));
    // Corners far off the frame or not numbers: no answer, and no endless walk.
    std::array<cv::Point2d, 4> wild = corners;
    wild[1] = {1e300, 5}, wild[3] = {NAN, INFINITY};
    EXPECT_EQ(ring_noise(image, wild, {12, 12, 12, 12}, outside).responses, 0u);
    EXPECT_EQ(ring_noise(image, corners, {NAN, NAN, NAN, NAN}, outside).responses, 0u);
  }
}
