#include "kartograf/segmentation/plane_sampling.hpp"

#include <algorithm>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf::segmentation {

PointCloud sample_plane_points(const PointImage& points, const RgbImage* colors,
                               const PlaneSet& planes, const PlaneSamplingParams& params) {
  const LabelImage& labels = planes.labels;
  require(points.width() == labels.width() && points.height() == labels.height(),
          "plane sampling: the point image is " + std::to_string(points.width()) + "x" +
              std::to_string(points.height()) + " but the plane labels are " +
              std::to_string(labels.width()) + "x" + std::to_string(labels.height()));
  require(!colors || (colors->width() == labels.width() && colors->height() == labels.height()),
          "plane sampling: the colour image does not have the plane labels' size");

  // Pixels of each plane, in scan order (so the draw depends only on the seed).
  std::vector<std::vector<std::size_t>> pixels(planes.planes.size());
  const std::size_t pixel_count = labels.size();
  for (std::size_t i = 0; i < pixel_count; ++i) {
    const Label id = labels.data()[i];
    if (id == 0) continue;
    require(id <= planes.planes.size(),
            "plane sampling: pixel " + std::to_string(i) + " has plane id " + std::to_string(id) +
                " but there are " + std::to_string(planes.planes.size()) + " planes");
    if (points.data()[i].head<3>().allFinite()) pixels[id - 1].push_back(i);
  }

  PointCloud cloud;
  std::mt19937_64 random(params.seed);
  for (std::size_t p = 0; p < planes.planes.size(); ++p) {
    std::vector<std::size_t>& candidates = pixels[p];
    const std::size_t take = std::min(params.points_per_plane, candidates.size());
    // Partial Fisher-Yates: the first `take` entries become a uniform draw without replacement.
    for (std::size_t k = 0; k < take; ++k) {
      std::uniform_int_distribution<std::size_t> pick(k, candidates.size() - 1);
      std::swap(candidates[k], candidates[pick(random)]);
    }
    const Plane& plane = planes.planes[p];
    for (std::size_t k = 0; k < take; ++k) {
      const std::size_t i = candidates[k];
      const Eigen::Vector3d point = points.data()[i].head<3>().cast<double>();
      const Eigen::Vector3d projected =
          point - (plane.normal.dot(point) + plane.offset) * plane.normal;
      cloud.points.push_back(projected.cast<float>());
      cloud.normals.push_back(plane.normal.cast<float>());
      if (colors) cloud.colors.push_back(colors->data()[i]);
    }
  }
  return cloud;
}

}  // namespace kartograf::segmentation
