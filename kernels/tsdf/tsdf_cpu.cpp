// CPU wrapper of kernels/tsdf/tsdf.h (the atomics of the rule are std::atomic_ref on the host).
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_band.h"

namespace kartograf::kernels {

namespace {

using compute::detail::CpuDispatch;
using compute::detail::for_each_item;
using compute::detail::for_each_item_2d;

void touch(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* depth = call.buffer<const std::uint16_t>(0);
  auto* keys = call.buffer<uint64_t>(1);
  auto* stamps = call.buffer<uint>(2);
  auto* status = call.buffer<uint>(3);
  for_each_item_2d(call, [&](uint gx, uint gy) {
    const uint x = gx * params.step, y = gy * params.step;
    if (x >= params.width || y >= params.height) return;
    tsdf_touch_pixel(keys, stamps, status, x, y, depth[y * params.width + x], params);
  });
}

// One ordered loop: the blocks are numbered in slot order.
void assign(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* keys = call.buffer<const uint64_t>(0);
  auto* slot_blocks = call.buffer<uint>(1);
  auto* block_keys = call.buffer<uint64_t>(2);
  const auto* stamps = call.buffer<const uint>(3);
  auto* active_blocks = call.buffer<uint>(4);
  auto* status = call.buffer<uint>(5);
  for (uint slot = 0; slot < params.count; ++slot) {
    tsdf_assign_slot(keys, slot_blocks, block_keys, stamps, active_blocks, status, slot, params);
  }
}

void integrate(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* depth = call.buffer<const std::uint16_t>(0);
  const auto* colors = call.buffer<const uint>(1);
  const auto* active_blocks = call.buffer<const uint>(2);
  const auto* block_keys = call.buffer<const uint64_t>(3);
  auto* voxels = call.buffer<TsdfVoxel>(4);
  for_each_item(call, [&](uint i) {
    if (i >= params.count) return;
    const TsdfVoxelView view = tsdf_voxel_view(active_blocks, block_keys, i, params);
    if (view.pixel < 0 || !tsdf_fuses(depth[view.pixel], view.z, params)) return;
    const uint color = params.has_color != 0u ? colors[view.pixel] : 0u;
    voxels[view.voxel] = tsdf_fuse(voxels[view.voxel], depth[view.pixel], view.z, color, params);
  });
}

void raycast(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* keys = call.buffer<const uint64_t>(0);
  const auto* slot_blocks = call.buffer<const uint>(1);
  const auto* voxels = call.buffer<const TsdfVoxel>(2);
  auto* points = call.buffer<float4>(3);
  auto* colors = call.buffer<uint>(4);
  const float min_depth = static_cast<float>(params.min_units) * params.metres_per_unit;
  const float max_depth = static_cast<float>(params.max_units) * params.metres_per_unit;
  for_each_item_2d(call, [&](uint x, uint y) {
    if (x >= params.width || y >= params.height) return;
    const uint index = y * params.width + x;
    const float4 p = tsdf_cast_ray(keys, slot_blocks, voxels, x, y, min_depth, max_depth, params);
    points[index] = p;
    if (params.has_color != 0u) colors[index] = tsdf_color_at(keys, slot_blocks, voxels, p, params);
  });
}

void band(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfBandParams>();
  const auto* block_keys = call.buffer<const uint64_t>(0);
  const auto* voxels = call.buffer<const TsdfVoxel>(1);
  auto* cells = call.buffer<uint>(2);
  for_each_item(call, [&](uint i) {
    if (i >= params.count) return;
    const TsdfBandMark mark = tsdf_band_mark(voxels[i], block_keys[i / KG_TSDF_BLOCK_VOXELS],
                                             i % KG_TSDF_BLOCK_VOXELS, params);
    if (mark.cell >= 0) kg_atomic_max_u32(cells, static_cast<uint>(mark.cell), mark.state);
  });
}

}  // namespace

void register_tsdf_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("tsdf_touch", touch);
  registry.add("tsdf_assign", assign);
  registry.add("tsdf_integrate", integrate);
  registry.add("tsdf_raycast", raycast);
  registry.add("tsdf_band", band);
}

}  // namespace kartograf::kernels
