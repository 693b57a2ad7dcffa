#pragma once
// Point generation on extracted planes (docs/methods.md M1 step 5, the paper's eq. 8-10): every
// pixel of a plane is projected onto it, P' = P - (n . P + offset) n (eq. 8-9 with |n| = 1), and
// points_per_plane of them (all when fewer) are drawn at random without replacement. ICP on these
// few points per plane (M1 step 6) replaces ICP on every point of the frame.
#include <cstddef>
#include <cstdint>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"

namespace kartograf::segmentation {

struct PlaneSamplingParams {
  std::size_t points_per_plane = 200;  // the paper's N
  std::uint64_t seed = 1;              // the draw is deterministic given the seed
};

// The projected sample of every plane of `planes` (planes.labels gives the pixels; points and, when
// given, colors have its size). The cloud's normals are the planes' normals; its colours the
// pixels' (none without colors). Points are grouped by plane, planes in id order.
// Throws Error on a size mismatch or a label without a plane.
PointCloud sample_plane_points(const PointImage& points, const RgbImage* colors,
                               const PlaneSet& planes, const PlaneSamplingParams& params = {});

}  // namespace kartograf::segmentation
