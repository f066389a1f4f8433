#include "covtrack/emulators/fiducial/tag_renderer.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace covtrack::fiducial {
namespace {

// Texture pixels per tag cell: fine enough that the bilinear warp's own blur is far
// below a sub-sample.
constexpr int kTexelsPerCell = 24;

}  // namespace

cv::Matx33d tag_plane_to_image(const Camera& camera, const Pose& T_camera_tag) {
  const Mat3 R = T_camera_tag.rotation();
  const Vec3 t = T_camera_tag.translation();
  const cv::Matx33d Rt(R(0, 0), R(0, 1), t.x(), R(1, 0), R(1, 1), t.y(), R(2, 0), R(2, 1), t.z());
  return camera_matrix(camera) * Rt;
}

std::vector<cv::Point2d> projected_corners(const Camera& camera, const RenderedTag& tag) {
  const double h = tag.size_m / 2;
  const Vec3 corners[4] = {{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0}};
  std::vector<cv::Point2d> out;
  for (const Vec3& c : corners) out.push_back(pinhole_pixel(camera, tag.T_camera_tag * c));
  return out;
}

cv::Mat render_tags(const Camera& camera, const TagFamily& family,
                    const std::vector<RenderedTag>& tags, const RenderLook& look) {
  cv::Mat image(camera.height_px, camera.width_px, CV_32F, cv::Scalar(look.background));
  const int S = std::max(1, look.supersample);
  const int margin = std::max(0, look.margin_cells);
  const int total = family.cells_across_total() + 2 * margin;
  for (const RenderedTag& tag : tags) {
    auto cells = family.cells(tag.id);
    if (!cells) continue;
    cv::copyMakeBorder(*cells, *cells, margin, margin, margin, margin, cv::BORDER_CONSTANT, 255);
    const double cell_m = tag.size_m / family.cells_across_border();
    const double half_total_m = cell_m * total / 2;
    // The whole printed tag must be in front of the camera.
    bool in_front = true;
    std::vector<cv::Point2d> outline;
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0}) {
        const Vec3 p = tag.T_camera_tag * Vec3(sx * half_total_m, sy * half_total_m, 0);
        if (p.z() < 1e-3) in_front = false;
        else outline.push_back(pinhole_pixel(camera, p));
      }
    if (!in_front) continue;
    double u0 = 1e18, v0 = 1e18, u1 = -1e18, v1 = -1e18;
    for (const auto& p : outline)
      u0 = std::min(u0, p.x), v0 = std::min(v0, p.y), u1 = std::max(u1, p.x), v1 = std::max(v1, p.y);
    const cv::Rect roi = cv::Rect(cv::Point(static_cast<int>(std::floor(u0)) - 2,
                                            static_cast<int>(std::floor(v0)) - 2),
                                  cv::Point(static_cast<int>(std::ceil(u1)) + 3,
                                            static_cast<int>(std::ceil(v1)) + 3)) &
                         cv::Rect(0, 0, image.cols, image.rows);
    if (roi.empty()) continue;

    cv::Mat texture;
    cells->convertTo(texture, CV_32F, (look.white - look.black) / 255.0, look.black);
    cv::resize(texture, texture, {}, kTexelsPerCell, kTexelsPerCell, cv::INTER_NEAREST);
    // Texel index i has its centre at i in the warp; it covers [i - 0.5, i + 0.5] texels.
    const double m_per_texel = cell_m / kTexelsPerCell;
    const cv::Matx33d texel_to_plane(m_per_texel, 0, -half_total_m + m_per_texel / 2,  //
                                     0, m_per_texel, -half_total_m + m_per_texel / 2,  //
                                     0, 0, 1);
    // Image pixel u (centre at integer u) to sub-sample index j inside the ROI:
    // sub-sample j covers pixel coordinates [(j)/S - 0.5, (j+1)/S - 0.5].
    const cv::Matx33d image_to_sub(S, 0, (S - 1) / 2.0 - S * roi.x,  //
                                   0, S, (S - 1) / 2.0 - S * roi.y,  //
                                   0, 0, 1);
    const cv::Matx33d H = image_to_sub * tag_plane_to_image(camera, tag.T_camera_tag) * texel_to_plane;
    // The printed tag and its footprint (1 where a sub-sample lies on it), both averaged
    // down, so that only what the tag covers is replaced: on a rolled board, neighbouring
    // tags' bounding boxes overlap, and pasting the whole box (background included) cut
    // the corners off the tags drawn before (their edges were then off by up to 1 px).
    cv::Mat fine(roi.height * S, roi.width * S, CV_32F, cv::Scalar(0));
    cv::Mat footprint = fine.clone();
    cv::warpPerspective(texture, fine, H, fine.size(), cv::INTER_LINEAR, cv::BORDER_TRANSPARENT);
    cv::warpPerspective(cv::Mat(texture.size(), CV_32F, cv::Scalar(1)), footprint, H, fine.size(), cv::INTER_LINEAR,
                        cv::BORDER_TRANSPARENT);
    cv::Mat coarse, covered;
    cv::resize(fine, coarse, roi.size(), 0, 0, cv::INTER_AREA);
    cv::resize(footprint, covered, roi.size(), 0, 0, cv::INTER_AREA);
    const cv::Mat blended = image(roi).mul(1 - covered) + coarse;
    blended.copyTo(image(roi));
  }
  if (look.blur_sigma_px > 0) cv::GaussianBlur(image, image, {0, 0}, look.blur_sigma_px);
  return image;
}

cv::Mat add_sensor_noise(const cv::Mat& clean, double noise_sigma, std::mt19937_64& rng) {
  cv::Mat out(clean.size(), CV_8U);
  std::normal_distribution<float> n(0.f, static_cast<float>(noise_sigma));
  for (int r = 0; r < clean.rows; ++r) {
    const float* in = clean.ptr<float>(r);
    std::uint8_t* o = out.ptr<std::uint8_t>(r);
    for (int c = 0; c < clean.cols; ++c)
      o[c] = cv::saturate_cast<std::uint8_t>(in[c] + (noise_sigma > 0 ? n(rng) : 0.f));
  }
  return out;
}

}  // namespace covtrack::fiducial
