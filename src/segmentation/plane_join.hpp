#pragma once
// What the two passes of merge_segments (plane_merge.hpp) share, and the second pass: joining
// adjacent merged planes (plane_join.cpp).
#include <span>

#include <Eigen/Core>

#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/plane_merge.hpp"

namespace kartograf::segmentation::detail {

// The distance allowance at `at` for a plane with `plane`'s normal.
inline double allowance(const PlaneMergeParams& params, const Eigen::Vector3d& at,
                        const SegmentPlane& plane) {
  return distance_allowance(params, at, plane.normal);
}

// Second pass: joins adjacent merged planes, lowest cost first (cost: RMS of the joint fit over the
// allowance at its depth; joins only below 1 and within the angle), then drops the absorbed planes
// and renumbers the rest in order. From `inputs`: `points` (may be null) enables the see-through
// test; `pixel_sums` (may be empty: summed over the labels then) are each segment's pixel x and
// y sums and count; `segment_at` (may be empty: the labels are read then) each pixel's segment.
void join_adjacent_planes(const SegmentLabelImage& labels, const MergeInputs& inputs,
                          const PlaneMergeParams& params, const Eigen::Vector3d& origin,
                          MergedPlanes& merged);

}  // namespace kartograf::segmentation::detail
