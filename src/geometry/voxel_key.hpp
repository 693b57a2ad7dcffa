#pragma once
// Voxel keys and their open-addressing hash, shared by voxel downsampling and the voxel-hash
// nearest-neighbour grid; the same arithmetic as shaders/voxel_hash.glsl and
// kernels/voxel_common.cl. A voxel (kx, ky, kz) = floor(p * inverse_size), each in [-2^20, 2^20),
// is stored as the 64-bit key 1 + (kx + 2^20) | (ky + 2^20) << 21 | (kz + 2^20) << 42, so 0 marks
// an empty slot.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace kartograf::geometry::detail {

inline constexpr double kVoxelLimit = 1048576.0;  // 2^20
inline constexpr std::uint64_t kEmptyVoxelKey = 0;

// floor(scaled) per axis; false when a coordinate is outside [-2^20, 2^20) or not finite.
inline bool voxel_of(const Eigen::Vector3d& scaled, Eigen::Vector3d& voxel) {
  voxel = Eigen::Vector3d(std::floor(scaled.x()), std::floor(scaled.y()), std::floor(scaled.z()));
  return voxel.x() >= -kVoxelLimit && voxel.y() >= -kVoxelLimit && voxel.z() >= -kVoxelLimit &&
         voxel.x() < kVoxelLimit && voxel.y() < kVoxelLimit && voxel.z() < kVoxelLimit;
}

inline std::uint64_t voxel_key(const Eigen::Vector3d& voxel) {
  const auto biased = [](double k) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(k) + 1048576);
  };
  return 1 + (biased(voxel.x()) | biased(voxel.y()) << 21 | biased(voxel.z()) << 42);
}

inline Eigen::Vector3d voxel_of_key(std::uint64_t key) {
  const std::uint64_t biased = key - 1;
  const auto axis = [&](int shift) {
    return static_cast<double>(static_cast<std::int64_t>((biased >> shift) & 0x1fffff) - 1048576);
  };
  return {axis(0), axis(21), axis(42)};
}

// The first slot to probe (Fibonacci hashing); probing walks slot + 1, + 2, ... mod capacity.
inline std::uint32_t voxel_slot(std::uint64_t key, unsigned capacity_log2) {
  return static_cast<std::uint32_t>((key * 0x9e3779b97f4a7c15ull) >> (64 - capacity_log2));
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
