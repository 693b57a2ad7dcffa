#pragma once
// The voxel-key rule of kernels/voxel_hash/voxel_hash.h for host code that works in Eigen (the
// host-built tables of registration/voxel_hash_correspondences.cpp and mapping/map_fusion.cpp),
// and the sizing of those tables.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "kernels/voxel_hash/voxel_hash.h"

namespace kartograf::geometry::detail {

inline constexpr double kVoxelLimit = KG_VOXEL_LIMIT;
inline constexpr std::uint64_t kEmptyVoxelKey = KG_EMPTY_VOXEL_KEY;

inline kernels::double3 to_double3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

// floor(scaled) per axis; false when a coordinate is outside [-2^20, 2^20) or not finite.
inline bool voxel_of(const Eigen::Vector3d& scaled, Eigen::Vector3d& voxel) {
  const kernels::double3 floored = kernels::voxel_floor(to_double3(scaled));
  voxel = Eigen::Vector3d(floored.x, floored.y, floored.z);
  return kernels::voxel_in_range(floored);
}

inline std::uint64_t voxel_key(const Eigen::Vector3d& voxel) {
  return kernels::voxel_key(to_double3(voxel));
}

inline Eigen::Vector3d voxel_of_key(std::uint64_t key) {
  const kernels::double3 voxel = kernels::voxel_of_key(key);
  return {voxel.x, voxel.y, voxel.z};
}

inline std::uint32_t voxel_slot(std::uint64_t key, unsigned capacity_log2) {
  return kernels::voxel_slot(key, capacity_log2);
}

// log2 of the table capacity for `entries` keys: a power of two >= 2 x entries (load <= 1/2,
// short probes), at least 64.
inline unsigned hash_capacity_log2(std::size_t entries) {
  return static_cast<unsigned>(std::bit_width(std::max<std::size_t>(entries * 2, 64) - 1));
}

// The largest power of two s with total_bound * s < 2^62: fixed-point sums of terms whose
// magnitudes add up to at most total_bound cannot overflow int64.
inline float fixed_point_scale(double total_bound) {
  return static_cast<float>(std::exp2(std::floor(62.0 - std::log2(std::max(1.0, total_bound)))));
}

}  // namespace kartograf::geometry::detail
