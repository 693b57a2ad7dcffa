#pragma once
// Per-label moments of an organized or unorganized cloud (count, sum p, sum p p^T), the input of
// the per-segment plane fits of docs/methods.md M1 step 3, for up to 65,536 labels in one pass.
//
// Every point adds its terms, relative to `origin`, as 64-bit fixed-point integers with atomic
// adds: integer sums are exact and order-independent, so every backend returns bit-identical
// results run to run. Terms are computed in double and rounded to 2^-k with k chosen from the
// point count and max_offset so that no sum can overflow (relative error < 1e-9 for typical
// segments; see docs/architecture.md).
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::geometry {

inline constexpr std::uint32_t kNoLabel = 0xffffffffu;  // pixels that belong to no segment
inline constexpr std::uint32_t kMaxSegmentLabels = 65536;

struct SegmentMomentParams {
  std::uint32_t label_count = 0;  // labels are 0..label_count-1; kNoLabel is skipped
  // Moments are taken about origin (e.g. a rough centroid of the cloud). Points farther than
  // max_offset from it in any coordinate are an error (their terms could overflow).
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  float max_offset = 64.0f;
};

struct SegmentMoments {
  std::uint64_t count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();        // sum (p - origin)
  Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();  // sum (p - origin)(p - origin)^T
};

// The moments of two disjoint point sets together (both about the same origin).
inline SegmentMoments& operator+=(SegmentMoments& into, const SegmentMoments& m) {
  into.count += m.count;
  into.sum += m.sum;
  into.sum_outer += m.sum_outer;
  return into;
}

struct SegmentMomentSet {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<SegmentMoments> segments;  // indexed by label

  Eigen::Vector3d centroid(std::uint32_t label) const;
  // Covariance about the centroid, normalised by the count (zero for empty segments).
  Eigen::Matrix3d covariance(std::uint32_t label) const;
};

// The reducer's fixed-point scales (its terms are those of kernels/segment_moments), and the
// moments its integer sums stand for.
class FixedPointMoments {
 public:
  using Sums = std::array<std::int64_t, 10>;  // count, sum d (3), sum d d^T (xx xy xz yy yz zz)

  // point_count: the length of the cloud the labels cover (it sets the fixed-point scales).
  FixedPointMoments(std::size_t point_count, const SegmentMomentParams& params);

  SegmentMoments moments(const Sums& sums) const;

  float first_scale() const { return static_cast<float>(first_scale_); }
  float second_scale() const { return static_cast<float>(second_scale_); }

 private:
  double first_scale_;
  double second_scale_;
};

// Keeps the device accumulators between calls (one frame after another allocates nothing).
class SegmentMomentReducer {
 public:
  explicit SegmentMomentReducer(const compute::Context& context);

  // points and labels have the same length. Throws Error for a label >= label_count (other than
  // kNoLabel), a point beyond max_offset, or label_count outside 1..65536.
  SegmentMomentSet run(const compute::Buffer<Point4f>& points,
                       const compute::Buffer<std::uint32_t>& labels,
                       const SegmentMomentParams& params);

 private:
  const compute::Context* context_;
  compute::Buffer<std::int64_t> moments_;
  compute::Buffer<std::uint32_t> status_;
};

// The CPU reference on host data, with the same fixed-point arithmetic (bit-identical sums) and
// any number of labels.
SegmentMomentSet segment_moments(std::span<const Point4f> points,
                                 std::span<const std::uint32_t> labels,
                                 const SegmentMomentParams& params);

// One-off convenience over SegmentMomentReducer.
SegmentMomentSet segment_moments(const compute::Context& context,
                                 const compute::Buffer<Point4f>& points,
                                 const compute::Buffer<std::uint32_t>& labels,
                                 const SegmentMomentParams& params);

}  // namespace kartograf::geometry
