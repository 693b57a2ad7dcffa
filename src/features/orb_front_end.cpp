// ORB features and their alignment in 3-D (features/orb_front_end.hpp).
#include "kartograf/features/orb_front_end.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "features/orb_description.hpp"
#include "features/orb_matching.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::features {
namespace {

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

void check_inputs(const DepthImage& depth, const RgbImage& color, const PinholeIntrinsics& camera,
                  double units_per_metre) {
  camera.validate("ORB features");
  require(depth.width() == camera.width && depth.height() == camera.height,
          "ORB features: depth image is " + size_text(depth.width(), depth.height()) +
              " but the camera is " + size_text(camera.width, camera.height));
  require(!color.empty(), "ORB features: the colour image is empty (features need colour)");
  require(color.width() == depth.width() && color.height() == depth.height(),
          "ORB features: colour image is " + size_text(color.width(), color.height()) +
              " but the depth image is " + size_text(depth.width(), depth.height()));
  require(std::isfinite(units_per_metre) && units_per_metre > 0,
          "ORB features: depth units per metre must be positive, got " +
              std::to_string(units_per_metre));
}

cv::Mat grey_of(const RgbImage& color) {
  static_assert(sizeof(Rgb8) == 3, "RgbImage pixels must be packed bytes");
  // OpenCV only reads through this header: the const_cast never writes.
  const cv::Mat rgb(
      color.height(), color.width(), CV_8UC3,
      const_cast<Rgb8*>(color.data()));  // NOLINT(cppcoreguidelines-pro-type-const-cast)
  cv::Mat grey;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  return grey;
}

// The depth (metres) at pixel (x, y) when it and its 3x3 neighbourhood agree, else 0: a corner on
// an object's outline would otherwise take the depth of whichever side its pixel fell on.
double stable_depth(const DepthImage& depth, int x, int y, double units_per_metre,
                    double max_spread) {
  if (x < 1 || y < 1 || x >= depth.width() - 1 || y >= depth.height() - 1) return 0;
  const std::uint16_t centre = depth(x, y);
  if (centre == 0) return 0;
  std::uint16_t low = centre, high = centre;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const std::uint16_t d = depth(x + dx, y + dy);
      if (d == 0) return 0;
      low = std::min(low, d);
      high = std::max(high, d);
    }
  if (high - low > max_spread * centre) return 0;
  return centre / units_per_metre;
}

// Where a colour keypoint falls on the depth image when the colour camera's focal length is
// `focal_ratio` times the depth camera's (same principal point and axis).
cv::Point2f on_depth_grid(const cv::Point2f& color_pixel, const PinholeIntrinsics& depth_camera,
                          double focal_ratio) {
  if (focal_ratio == 1.0) return color_pixel;
  const double k = 1.0 / focal_ratio;
  return {static_cast<float>(depth_camera.cx + (color_pixel.x - depth_camera.cx) * k),
          static_cast<float>(depth_camera.cy + (color_pixel.y - depth_camera.cy) * k)};
}

std::vector<cv::KeyPoint> detect(const cv::Mat& grey, cv::Mat& descriptors, const OrbParams& p) {
  // One detector per call: cv::ORB's methods are not documented as safe to share across threads.
  const cv::Ptr<cv::ORB> orb =
      cv::ORB::create(p.features_per_frame, static_cast<float>(p.scale_factor), p.levels, 31, 0, 2,
                      cv::ORB::HARRIS_SCORE, 31, p.fast_threshold);
  std::vector<cv::KeyPoint> keypoints;
  orb->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
  return keypoints;
}

}  // namespace

OrbFrontEnd::OrbFrontEnd(const OrbParams& params) : params_(params) {
  require(params.features_per_frame > 0, "ORB: features_per_frame must be positive");
  require(params.scale_factor > 1, "ORB: scale_factor must be above 1");
  require(params.levels >= 1, "ORB: levels must be at least 1");
  require(params.fast_threshold > 0, "ORB: fast_threshold must be positive");
  require(params.ratio > 0 && params.ratio <= 1, "ORB: ratio must be in (0, 1]");
  require(params.max_depth_m > 0, "ORB: max_depth_m must be positive");
  require(params.max_local_depth_spread >= 0, "ORB: max_local_depth_spread must not be negative");
  require(params.color_to_depth_focal > 0, "ORB: color_to_depth_focal must be positive");
  require(params.ransac.min_inliers >= 3, "ORB: ransac.min_inliers must be at least 3");
}

std::shared_ptr<const registration::FeatureDescription> OrbFrontEnd::describe(
    const DepthImage& depth, const RgbImage& color, const PinholeIntrinsics& camera,
    double units_per_metre) const {
  check_inputs(depth, color, camera, units_per_metre);
  cv::Mat all_descriptors;
  std::vector<cv::KeyPoint> keypoints = detect(grey_of(color), all_descriptors, params_);
  // Strongest corners first, so that a user of fewer features (the place index) takes a prefix.
  std::vector<std::size_t> order(keypoints.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return keypoints[a].response > keypoints[b].response;
  });
  cv::Mat kept_descriptors;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2f> kept_keypoints;
  for (const std::size_t i : order) {
    const cv::Point2f at = on_depth_grid(keypoints[i].pt, camera, params_.color_to_depth_focal);
    const double z = stable_depth(depth, static_cast<int>(std::lround(at.x)),
                                  static_cast<int>(std::lround(at.y)), units_per_metre,
                                  params_.max_local_depth_spread);
    if (z <= 0 || z > params_.max_depth_m) continue;
    // The keypoint's sub-pixel position, not the rounded one, for the ray.
    points.emplace_back((at.x - camera.cx) * z / camera.fx, (at.y - camera.cy) * z / camera.fy, z);
    kept_keypoints.emplace_back(at.x, at.y);
    kept_descriptors.push_back(all_descriptors.row(static_cast<int>(i)));
  }
  return std::make_shared<const OrbDescription>(std::move(kept_descriptors), std::move(points),
                                                std::move(kept_keypoints));
}

std::optional<registration::FeatureAlignment> OrbFrontEnd::align(
    const registration::FeatureDescription& source,
    const registration::FeatureDescription& target) const {
  const OrbDescription& from = as_orb(source, "ORB alignment (source)");
  const OrbDescription& to = as_orb(target, "ORB alignment (target)");
  const std::vector<DescriptorMatch> matches =
      ratio_matches(from.descriptors(), to.descriptors(), params_.ratio, params_.cross_check);
  if (matches.size() < params_.ransac.min_inliers) return std::nullopt;
  std::vector<Eigen::Vector3d> source_points, target_points;
  source_points.reserve(matches.size());
  target_points.reserve(matches.size());
  for (const DescriptorMatch& m : matches) {
    source_points.push_back(from.points()[static_cast<std::size_t>(m.source)]);
    target_points.push_back(to.points()[static_cast<std::size_t>(m.target)]);
  }
  const auto consensus =
      registration::estimate_rigid_ransac(source_points, target_points, params_.ransac);
  if (!consensus) return std::nullopt;
  registration::FeatureAlignment alignment;
  alignment.source_to_target = consensus->source_to_target;
  alignment.matches = matches.size();
  alignment.inliers = consensus->inliers;
  alignment.inlier_rmse_m = consensus->inlier_rmse_m;
  return alignment;
}

std::vector<std::uint8_t> OrbFrontEnd::serialize(
    const registration::FeatureDescription& description) const {
  return features::serialize(as_orb(description, "ORB serialisation"));
}

std::shared_ptr<const registration::FeatureDescription> OrbFrontEnd::deserialize(
    std::span<const std::uint8_t> bytes) const {
  return deserialize_orb(bytes);
}

std::unique_ptr<registration::PlaceIndex> OrbFrontEnd::make_place_index() const {
  return std::make_unique<OrbPlaceIndex>(params_.places);
}

}  // namespace kartograf::features
