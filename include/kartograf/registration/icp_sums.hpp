#pragma once
// The reductions at the heart of every ICP iteration: over all correspondences (p_i, q_j(i)),
// the 3x3 cross-covariance with centroids (point-to-point, closed-form SVD) and the 6x6 normal
// equations (point-to-plane, Gauss-Newton). Two passes, no atomics: per-work-group partial sums,
// then one fixed-order final pass, so results are reproducible run to run. Per-pair arithmetic and
// accumulation are in double: relative error vs an all-double reference is ~1e-12.
// Pair weights are the caller's per-source weight times a robust kernel of the residual
// (robust_kernel.hpp), so one reduction is one iteratively reweighted least-squares step.
#include <cstdint>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/registration/robust_kernel.hpp"

namespace kartograf::registration {

// Correspondence entries below 0: kNoMatch means the source point was looked at and has no partner
// (it counts as "considered", the denominator of ICP's fitness); kNotSelected (or lower) means it
// was left out by point selection (e.g. 1-in-k subsampling).
inline constexpr std::int32_t kNoMatch = -1;
inline constexpr std::int32_t kNotSelected = -2;

// Pair i is (R source[i] + t, target[j]) with j = correspondences[i], or j = i without that buffer.
// A pair counts when source, target (and normal) are valid points, j is in range, its weight is
// > 0, and |R p + t - q| <= max_distance. Its weight in the sums is the caller's weight (1 without
// the buffer) times robust_weight(robust, residual); a pair the kernel weights 0 still counts.
struct Correspondences {
  const compute::Buffer<Point4f>* source = nullptr;
  const compute::Buffer<Point4f>* target = nullptr;
  const compute::Buffer<Point4f>* target_normals = nullptr;        // point-to-plane only
  const compute::Buffer<std::int32_t>* correspondences = nullptr;  // optional
  const compute::Buffer<float>* weights = nullptr;                 // optional, per source point
  Eigen::Isometry3d source_to_target = Eigen::Isometry3d::Identity();
  double max_distance = std::numeric_limits<double>::infinity();
  RobustLoss robust;
};

struct PointToPointSums {
  std::uint64_t pair_count = 0;
  double weight_sum = 0;
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero();  // weighted mean of R p + t
  Eigen::Vector3d target_mean = Eigen::Vector3d::Zero();
  // sum w (R p + t - source_mean)(q - target_mean)^T, not normalised.
  Eigen::Matrix3d cross_covariance = Eigen::Matrix3d::Zero();
  double squared_error_sum = 0;  // sum w |R p + t - q|^2
  // sum w (R p + t - source_mean)(R p + t - source_mean)^T: the point-to-point J^T J needs it.
  Eigen::Matrix3d source_scatter = Eigen::Matrix3d::Zero();
  double unweighted_squared_error_sum = 0;  // sum |R p + t - q|^2 over the counted pairs
  std::uint64_t considered_count = 0;       // valid source points whose entry is not kNotSelected
};

// The linearisation about `pivot`: a small motion x = (omega, v) moves p' to
// p' + omega x (p' - pivot) + v, so the update is applied as T(pivot) exp(x) T(-pivot).
struct PointToPlaneSystem {
  std::uint64_t pair_count = 0;
  double weight_sum = 0;
  Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();  // sum w J^T J
  Eigen::Matrix<double, 6, 1> jtr = Eigen::Matrix<double, 6, 1>::Zero();  // sum w J^T r
  double squared_error_sum = 0;                                           // sum w r^2
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  double unweighted_squared_error_sum = 0;  // sum r^2 over the counted pairs
  std::uint64_t considered_count = 0;       // valid source points whose entry is not kNotSelected
};

// Holds the device scratch buffers, so that ICP iterations allocate nothing.
class IcpReduction {
 public:
  explicit IcpReduction(const compute::Context& context);

  // Sums relative to rough centroids (pivots) keep the sums well conditioned; any nearby point
  // works, e.g. the previous iteration's means.
  PointToPointSums point_to_point(const Correspondences& pairs,
                                  const Eigen::Vector3d& source_pivot = Eigen::Vector3d::Zero(),
                                  const Eigen::Vector3d& target_pivot = Eigen::Vector3d::Zero());
  PointToPlaneSystem point_to_plane(const Correspondences& pairs,
                                    const Eigen::Vector3d& pivot = Eigen::Vector3d::Zero());

 private:
  const compute::Context* context_;
  compute::Buffer<double> frame_;     // R, t, pivots, max distance^2, robust scale
  compute::Buffer<double> partials_;  // one row per work-group
  compute::Buffer<double> result_;    // the final row
};

}  // namespace kartograf::registration
