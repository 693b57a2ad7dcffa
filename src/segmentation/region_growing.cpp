#include "kartograf/segmentation/region_growing.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace kartograf::segmentation {

namespace {

constexpr int kNeighbourDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kNeighbourDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

}  // namespace

SegmentLabelImage grow_regions_lab(const LabImage& lab, const PointImage& points,
                                   const RegionGrowingParams& params) {
  require(lab.width() == points.width() && lab.height() == points.height(),
          "grow_regions_lab: Lab image is " + std::to_string(lab.width()) + "x" +
              std::to_string(lab.height()) + " but the point image is " +
              std::to_string(points.width()) + "x" + std::to_string(points.height()));
  require(std::isfinite(params.lab_threshold) && params.lab_threshold > 0,
          "grow_regions_lab: lab_threshold must be positive, got " +
              std::to_string(params.lab_threshold));
  require(std::isfinite(params.max_depth_jump) && params.max_depth_jump >= 0,
          "grow_regions_lab: max_depth_jump must be >= 0 (0 = off), got " +
              std::to_string(params.max_depth_jump));

  require(params.tile_size >= 0, "grow_regions_lab: tile_size must be >= 0 (0 = off), got " +
                                     std::to_string(params.tile_size));

  const int width = lab.width(), height = lab.height();
  SegmentLabelImage labels(width, height, geometry::kNoLabel);
  if (labels.empty()) return labels;

  std::uint32_t* label = labels.data();
  const Eigen::Vector4f* colour = lab.data();
  const Point4f* point = points.data();
  const float threshold_squared = params.lab_threshold * params.lab_threshold;
  const float jump = params.max_depth_jump;
  const int tile = params.tile_size > 0 ? params.tile_size : std::max(width, height);

  // A pixel is pushed only while unlabelled and valid: both facts are re-checked on pop (labels
  // never change back), so the result is the paper's; skipping the pushes just keeps the stack
  // small. The depth test depends only on the pair (popped pixel, neighbour), so it is applied
  // when pushing.
  std::vector<std::uint32_t> stack;
  stack.reserve(std::size_t{1} << 16);
  std::uint32_t next_label = 0;
  for (int seed_y = 0; seed_y < height; ++seed_y) {
    for (int seed_x = 0; seed_x < width; ++seed_x) {
      const std::size_t seed = static_cast<std::size_t>(seed_y) * width + seed_x;
      if (label[seed] != geometry::kNoLabel || !is_valid(point[seed])) continue;
      const std::uint32_t id = next_label++;
      // The seed's tile bounds the segment (the whole image when tiling is off).
      const int x0 = seed_x / tile * tile, y0 = seed_y / tile * tile;
      const int x1 = std::min(width, x0 + tile), y1 = std::min(height, y0 + tile);
      Eigen::Vector4f mean = colour[seed];
      float count = 0.0f;
      stack.push_back(static_cast<std::uint32_t>(seed));
      while (!stack.empty()) {
        const std::uint32_t pixel = stack.back();
        stack.pop_back();
        if (label[pixel] != geometry::kNoLabel) continue;
        const Eigen::Vector4f difference = colour[pixel] - mean;
        if (difference.squaredNorm() >= threshold_squared) continue;
        label[pixel] = id;
        count += 1.0f;
        mean += difference / count;  // eq. 5: c(t+1) = c(t) + (x - c(t)) / (t + 1)
        const int x = static_cast<int>(pixel % static_cast<std::uint32_t>(width));
        const int y = static_cast<int>(pixel / static_cast<std::uint32_t>(width));
        const float depth = point[pixel].z();
        for (int k = 0; k < 8; ++k) {
          const int nx = x + kNeighbourDx[k], ny = y + kNeighbourDy[k];
          if (nx < x0 || ny < y0 || nx >= x1 || ny >= y1) continue;
          const std::uint32_t neighbour = static_cast<std::uint32_t>(ny * width + nx);
          if (label[neighbour] != geometry::kNoLabel) continue;
          const float neighbour_depth = point[neighbour].z();
          if (std::isnan(neighbour_depth)) continue;
          if (jump > 0.0f && std::fabs(neighbour_depth - depth) > jump * depth) continue;
          stack.push_back(neighbour);
        }
      }
    }
  }
  return labels;
}

std::uint32_t segment_count(const SegmentLabelImage& labels) {
  std::uint32_t count = 0;
  for (const std::uint32_t l : labels.pixels())
    if (l != geometry::kNoLabel) count = std::max(count, l + 1);
  return count;
}

}  // namespace kartograf::segmentation
