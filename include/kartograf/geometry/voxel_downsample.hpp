#pragma once
// Voxel-grid downsampling of an unorganized cloud: one point per occupied voxel, the centroid of
// its points, with the re-normalised mean of their normals and the mean of their colours. Makes
// clouds of even density (a map, a scan) small enough for k-d trees and ICP.
//
// Rules, identical on every backend:
//   voxel of a valid point p: floor(p * s) per axis in double, s = float(1 / voxel_size) (so the
//     voxel edge is 1/s, within 6e-8 of voxel_size relative); each index must be in
//     [-2^20, 2^20) (else Error: ~52 km at 5 cm). Invalid (NaN) points are skipped.
//   order: voxels in the order of their first (lowest-index) point.
//   point: the centroid (x, y, z, 1).
//   normal: the sum of the voxel's valid normals, normalised; all-NaN when there is none or when
//     they cancel (|sum| < 1e-3 x their count). A component beyond +-2 is an Error (not unit).
//   colour: per-channel mean rounded half up, packed like the input.
// Sums are 64-bit fixed-point integers (positions within the voxel in [0, 1), scale 2^k with
// n 2^k <= 2^62; normals likewise), added with integer atomics: exact and order-independent, so
// every backend sums the same integers. Only the final division and rounding to float may differ
// by a float ulp: centroids agree with the CPU backend within 1e-6 m (|coordinates| < 8 m), normals
// within 1e-6, colours exactly; against an all-double reference within the same bounds.
//
// Every backend, the CPU included, runs the six passes of kernels/voxel_downsample (hash insert,
// per-thread counts, scan, numbering in first-point order, fixed-point accumulation,
// finalisation) and waits once, for the voxel count.
#include <cstdint>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/geometry/subsample.hpp"

namespace kartograf::geometry {

struct VoxelDownsampleParams {
  float voxel_size = 0.05f;  // metres
};

// Keeps the hash table and scratch buffers between calls on clouds of similar size.
class VoxelDownsampler {
 public:
  explicit VoxelDownsampler(const compute::Context& context);

  // Throws Error for voxel_size not finite and > 0, more than 2^26 points, mismatched
  // normals/colours, voxel indices out of range or non-unit normals.
  DeviceCloud run(const DeviceCloud& cloud, const VoxelDownsampleParams& params);

 private:
  const compute::Context* context_;
  compute::Buffer<std::uint64_t> keys_;           // hash table: voxel key per slot
  compute::Buffer<std::uint32_t> first_;          // per slot: 0xffffffff - lowest point index
  compute::Buffer<std::uint32_t> voxel_of_slot_;  // per slot: output voxel
  compute::Buffer<std::int32_t> point_slots_;     // per point: slot, -1 for skipped points
  compute::Buffer<std::uint32_t> counts_;         // per thread: first points, then offsets
  compute::Buffer<std::uint32_t> status_;         // out of range, table full, bad normals
};

// One-off convenience over VoxelDownsampler.
DeviceCloud voxel_downsample(const compute::Context& context, const DeviceCloud& cloud,
                             const VoxelDownsampleParams& params);

}  // namespace kartograf::geometry
