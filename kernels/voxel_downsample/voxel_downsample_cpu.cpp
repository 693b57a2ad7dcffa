// CPU wrapper of kernels/voxel_downsample/voxel_downsample.h (the six passes; the atomics of the
// rule are std::atomic_ref on the host).
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/voxel_downsample/voxel_downsample.h"

namespace kartograf::kernels {

namespace {

using compute::detail::CpuDispatch;
using compute::detail::for_each_item;

// body(t) for each thread t of an ordering pass: the threads' chunks share out `point_count`
// points, so that is the work that decides on parallelism.
template <class Body>
void for_each_chunk_thread(const CpuDispatch& call, uint point_count, Body&& body) {
  compute::detail::for_each_chunk(call.global_x(), point_count,
                                  [&](std::size_t first, std::size_t last, std::size_t) {
                                    for (std::size_t t = first; t < last; ++t) {
                                      body(static_cast<uint>(t));
                                    }
                                  });
}

void insert(const CpuDispatch& call) {
  const auto params = call.params_as<VoxelInsertParams>();
  const auto* points = call.buffer<const float4>(0);
  const auto* normals = call.buffer<const float4>(1);
  auto* keys = call.buffer<uint64_t>(2);
  auto* first = call.buffer<uint>(3);
  auto* point_slots = call.buffer<int>(4);
  auto* status = call.buffer<uint>(5);
  for_each_item(call, [&](uint i) {
    if (i >= params.point_count) return;
    const float4 n = params.has_normals != 0u ? normals[i] : KG_INVALID_POINT;
    point_slots[i] = voxel_insert_point(keys, first, status, i, points[i], n, params);
  });
}

void count(const CpuDispatch& call) {
  const auto params = call.params_as<VoxelChunkParams>();
  const auto* point_slots = call.buffer<const int>(0);
  const auto* first = call.buffer<const uint>(1);
  auto* counts = call.buffer<uint>(2);
  for_each_chunk_thread(call, params.point_count, [&](uint t) {
    counts[t] = voxel_count_first_points(point_slots, first, t, params);
  });
}

// The work-group's exclusive prefix sums, in order (the same sums).
void scan(const CpuDispatch& call) {
  const auto params = call.params_as<VoxelScanParams>();
  auto* counts = call.buffer<uint>(0);
  uint running = 0u;
  for (uint t = 0; t < params.thread_count; ++t) {
    const uint value = counts[t];
    counts[t] = running;
    running += value;
  }
  counts[params.thread_count] = running;
}

void assign(const CpuDispatch& call) {
  const auto params = call.params_as<VoxelChunkParams>();
  const auto* point_slots = call.buffer<const int>(0);
  const auto* first = call.buffer<const uint>(1);
  const auto* counts = call.buffer<const uint>(2);
  const auto* keys = call.buffer<const uint64_t>(3);
  auto* voxel_of_slot = call.buffer<uint>(4);
  auto* voxel_keys = call.buffer<uint64_t>(5);
  for_each_chunk_thread(call, params.point_count, [&](uint t) {
    voxel_assign_chunk(point_slots, first, counts, keys, voxel_of_slot, voxel_keys, t, params);
  });
}

// One ordered loop with plain adds: the same integer sums as the devices' atomics, without their
// cost.
void accumulate(const CpuDispatch& call) {
  const auto params = call.params_as<VoxelSumParams>();
  const auto* points = call.buffer<const float4>(0);
  const auto* normals = call.buffer<const float4>(1);
  const auto* colors = call.buffer<const uint>(2);
  const auto* point_slots = call.buffer<const int>(3);
  const auto* voxel_of_slot = call.buffer<const uint>(4);
  auto* sums = call.buffer<int64_t>(5);
  for (uint i = 0; i < params.count; ++i) {
    const int slot = point_slots[i];
    if (slot < 0) continue;
    int64_t terms[KG_VOXEL_MAX_SUMS];
    voxel_point_terms_at(points, normals, colors, terms, i, params);
    int64_t* voxel_sums = sums + std::size_t{voxel_of_slot[slot]} * params.stride;
    for (uint k = 0; k < params.stride; ++k) voxel_sums[k] += terms[k];
  }
}

void finalize(const CpuDispatch& call) {
  const auto params = call.params_as<VoxelSumParams>();
  const auto* voxel_keys = call.buffer<const uint64_t>(0);
  const auto* sums = call.buffer<const int64_t>(1);
  auto* out_points = call.buffer<float4>(2);
  auto* out_normals = call.buffer<float4>(3);
  auto* out_colors = call.buffer<uint>(4);
  for_each_item(call, [&](uint v) {
    if (v < params.count) {
      voxel_finalize(voxel_keys, sums, out_points, out_normals, out_colors, v, params);
    }
  });
}

}  // namespace

void register_voxel_downsample_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("voxel_downsample_insert", insert);
  registry.add("voxel_downsample_count", count);
  registry.add("voxel_downsample_scan", scan);
  registry.add("voxel_downsample_assign", assign);
  registry.add("voxel_downsample_accumulate", accumulate);
  registry.add("voxel_downsample_finalize", finalize);
}

}  // namespace kartograf::kernels
