// CPU wrapper of kernels/esdf/esdf3.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/esdf/esdf3.h"

namespace kartograf::kernels {

namespace {

using compute::detail::CpuDispatch;
using compute::detail::for_each_item;

void mark(const CpuDispatch& call) {
  const auto params = call.params_as<Esdf3Params>();
  const auto* blocks = call.buffer<const uint>(0);
  const auto* block_keys = call.buffer<const uint64_t>(1);
  const auto* voxels = call.buffer<const TsdfVoxel>(2);
  auto* marks = call.buffer<uint>(3);
  const uint side = KG_TSDF_BLOCK_SIDE / params.cell_voxels;
  const uint cells = side * side * side;
  for_each_item(call, [&](uint i) {
    if (i >= params.count) return;
    const uint block = blocks[i / cells];
    const int at = esdf3_mark_cell(block_keys[block], i % cells, params);
    if (at >= 0) marks[at] = esdf3_cell_mark(voxels, block, i % cells, params);
  });
}

void seed(const CpuDispatch& call) {
  const auto params = call.params_as<Esdf3Params>();
  const auto* marks = call.buffer<const uint>(0);
  auto* squared = call.buffer<int64_t>(1);
  for_each_item(call, [&](uint i) {
    if (i >= params.count) return;
    squared[i] =
        esdf3_seed_value(marks[esdf3_box_cell(i, params.box_x, params.box_y, params.box_z,
                                              params.box_dims_x, params.box_dims_y, params)]);
  });
}

void write(const CpuDispatch& call) {
  const auto params = call.params_as<Esdf3Params>();
  const auto* squared = call.buffer<const int64_t>(0);
  auto* distances = call.buffer<float>(1);
  for_each_item(call, [&](uint i) {
    if (i >= params.count) return;
    const uint at = esdf3_box_cell(i, params.box_x, params.box_y, params.box_z, params.box_dims_x,
                                   params.box_dims_y, params);
    distances[at] = esdf3_distance(squared[esdf3_outer_index(i, params)], params);
  });
}

}  // namespace

void register_esdf3_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("esdf3_mark", mark);
  registry.add("esdf3_seed", seed);
  registry.add("esdf3_write", write);
}

}  // namespace kartograf::kernels
