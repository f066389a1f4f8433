// The image-noise input of the corner model: a robust estimate of the sensor's white
// noise from one frame, which edges and smooth shading must not inflate.
#include <gtest/gtest.h>

#include <algorithm>
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
