// CPU wrapper of kernels/tsdf/tsdf.h (the atomics of the rule are std::atomic_ref on the host).
#include <array>

#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/tsdf/tsdf.h"
#include "kernels/tsdf/tsdf_band.h"
#include "kernels/tsdf/tsdf_mesh.h"

namespace kartograf::kernels {

// The loops below as vector code twice: for AVX2 (8 lanes, picked at load time where the CPU has
// it) and for the baseline; the integration's per-voxel loops also for AVX-512 (16 lanes). Without
// FMA (-ffp-contract=off for the CPU wrappers), so that every clone gives the rule's results bit
// for bit. The ray cast stays at AVX2: its AVX-512 code was slower (1 cm: 278 against 179 ms a
// frame), and frame-to-model tracking, which ray casts every frame, with it. So does the touch:
// AVX-512 gained it nothing (integration at 1 cm 8.6-9.2 ms either way).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define KG_CPU_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#define KG_CPU_WIDE_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define KG_CPU_VECTOR_CLONES
#define KG_CPU_WIDE_VECTOR_CLONES
#endif

namespace {

using compute::detail::CpuDispatch;
using compute::detail::for_each_item;
using compute::detail::for_each_item_2d;

// Blocks a thread touched recently (a direct-mapped cache: one compare): neighbouring rays cross
// mostly the same blocks, and a block already inserted and stamped in this pass needs neither
// again.
class RecentBlocks {
 public:
  // Whether key was seen; remembers it either way.
  bool seen(std::uint64_t key) {
    std::uint64_t& entry = keys_[(key ^ (key >> 21) ^ (key >> 42)) % keys_.size()];
    const bool hit = entry == key;
    entry = key;
    return hit;
  }

 private:
  std::array<std::uint64_t, 64> keys_{};  // 0 is no key (KG_EMPTY_VOXEL_KEY)
};

// Row y's touching pixels. A pixel without a valid depth has no walk: skipped before the ray's
// set-up.
KG_CPU_VECTOR_CLONES void touch_row(const std::uint16_t* depth, uint64_t* keys, uint* stamps,
                                    uint* status, uint y, const TsdfParams& params,
                                    RecentBlocks& recent) {
  for (uint x = 0; x < params.width; x += params.step) {
    const uint d = depth[y * params.width + x];
    if (!tsdf_depth_valid(d, params)) continue;
    TsdfSegmentWalk walk = tsdf_touch_walk(status, x, y, d, params);
    for (int i = 0; i < KG_TSDF_WALK_BLOCKS && walk.more != 0; ++i) {
      if (!recent.seen(tsdf_block_key(walk.x, walk.y, walk.z)))
        tsdf_touch_block(keys, stamps, status, walk.x, walk.y, walk.z, params);
      walk = tsdf_segment_step(walk);
    }
  }
}

void touch(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* depth = call.buffer<const std::uint16_t>(0);
  auto* keys = call.buffer<uint64_t>(1);
  auto* stamps = call.buffer<uint>(2);
  auto* status = call.buffer<uint>(3);
  const uint columns = (params.width + params.step - 1) / params.step;
  const uint rows = (params.height + params.step - 1) / params.step;
  compute::detail::for_each_chunk(
      rows, std::size_t{rows} * columns, [&](std::size_t first, std::size_t last, std::size_t) {
        RecentBlocks recent;
        for (std::size_t row = first; row < last; ++row)
          touch_row(depth, keys, stamps, status, static_cast<uint>(row) * params.step, params,
                    recent);
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

// Where the camera sees each voxel of the block with `key` (the rule's tsdf_voxel_in_camera and
// tsdf_pixel_of), as one loop over the block that the compiler turns into vector code.
KG_CPU_WIDE_VECTOR_CLONES void project_block(std::uint64_t key, const TsdfParams& params,
                                             int* __restrict pixels, float* __restrict depths) {
  const TsdfParams p = params;  // a local: the compiler then knows the stores leave it alone
  for (uint cell = 0; cell < KG_TSDF_BLOCK_VOXELS; ++cell) {
    const float3 c = tsdf_voxel_in_camera(key, cell, p);
    pixels[cell] = tsdf_pixel_of(c, p);
    depths[cell] = c.z;
  }
}

// The block's voxels after the frame: the rule's tsdf_fuse on each, as a loop without branches on
// the data (vector code). A voxel the camera does not see reads depth 0, which the rule ignores.
KG_CPU_WIDE_VECTOR_CLONES void fuse_block(TsdfVoxel* __restrict voxels,
                                          const int* __restrict pixels,
                                          const float* __restrict depths,
                                          const std::uint16_t* __restrict depth,
                                          const uint* __restrict colors, const TsdfParams& params) {
  alignas(64) uint seen_depth[KG_TSDF_BLOCK_VOXELS];
  alignas(64) uint seen_color[KG_TSDF_BLOCK_VOXELS];
  for (uint cell = 0; cell < KG_TSDF_BLOCK_VOXELS; ++cell) {
    const int pixel = pixels[cell];
    seen_depth[cell] = pixel >= 0 ? depth[pixel] : 0u;
    seen_color[cell] = pixel >= 0 && colors ? colors[pixel] : 0u;
  }
  const TsdfParams p = params;
  for (uint cell = 0; cell < KG_TSDF_BLOCK_VOXELS; ++cell) {
    TsdfVoxel voxel;  // field by field: the vectoriser takes no whole 12-byte structs
    voxel.tsdf = voxels[cell].tsdf;
    voxel.weight = voxels[cell].weight;
    voxel.color = voxels[cell].color;
    const TsdfVoxel fused = tsdf_fuse(voxel, seen_depth[cell], depths[cell], seen_color[cell], p);
    voxels[cell].tsdf = fused.tsdf;
    voxels[cell].weight = fused.weight;
    voxels[cell].color = fused.color;
  }
}

// Block by block: the projections first (vector code), then the voxels that change.
void integrate(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* depth = call.buffer<const std::uint16_t>(0);
  const auto* colors = call.buffer<const uint>(1);
  const auto* active_blocks = call.buffer<const uint>(2);
  const auto* block_keys = call.buffer<const uint64_t>(3);
  auto* voxels = call.buffer<TsdfVoxel>(4);
  const std::size_t blocks = params.count / KG_TSDF_BLOCK_VOXELS;
  compute::detail::for_each_chunk(
      blocks, params.count, [&](std::size_t first, std::size_t last, std::size_t) {
        alignas(64) int pixels[KG_TSDF_BLOCK_VOXELS];
        alignas(64) float depths[KG_TSDF_BLOCK_VOXELS];
        for (std::size_t b = first; b < last; ++b) {
          const uint block = active_blocks[b];
          project_block(block_keys[block], params, pixels, depths);
          fuse_block(voxels + std::size_t{block} * KG_TSDF_BLOCK_VOXELS, pixels, depths, depth,
                     params.has_color != 0u ? colors : nullptr, params);
        }
      });
}

// The buffers of a ray cast, as the wrapper reads them.
struct RaycastBuffers {
  const uint64_t* keys;
  const uint* slot_blocks;
  const TsdfVoxel* voxels;
  float4* points;
  uint* colors;
  const uint* ranges;
};

// Row y of the ray cast. An AVX2 clone too: there floor() is one instruction, not a call.
KG_CPU_VECTOR_CLONES void raycast_row(const RaycastBuffers& b, uint y, const TsdfParams& params) {
  const float min_depth = static_cast<float>(params.min_units) * params.metres_per_unit;
  const float max_depth = static_cast<float>(params.max_units) * params.metres_per_unit;
  for (uint x = 0; x < params.width; ++x) {
    const uint index = y * params.width + x;
    const TsdfDepthSpan span = tsdf_ray_span(b.ranges, x, y, min_depth, max_depth, params);
    const float4 p =
        tsdf_cast_ray(b.keys, b.slot_blocks, b.voxels, x, y, span.near, span.far, params);
    b.points[index] = p;
    if (params.has_color != 0u)
      b.colors[index] = tsdf_color_at(b.keys, b.slot_blocks, b.voxels, p, params);
  }
}

void raycast(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const RaycastBuffers buffers{
      call.buffer<const uint64_t>(0), call.buffer<const uint>(1), call.buffer<const TsdfVoxel>(2),
      call.buffer<float4>(3),         call.buffer<uint>(4),       call.buffer<const uint>(5)};
  compute::detail::for_each_chunk(params.height, std::size_t{params.width} * params.height,
                                  [&](std::size_t first, std::size_t last, std::size_t) {
                                    for (std::size_t y = first; y < last; ++y)
                                      raycast_row(buffers, static_cast<uint>(y), params);
                                  });
}

void range(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfParams>();
  const auto* block_keys = call.buffer<const uint64_t>(0);
  auto* ranges = call.buffer<uint>(1);
  for_each_item(call, [&](uint i) {
    if (i < params.count) tsdf_range_block(ranges, block_keys[i], params);
  });
}

void mesh(const CpuDispatch& call) {
  const auto params = call.params_as<TsdfMeshParams>();
  const auto* keys = call.buffer<const uint64_t>(0);
  const auto* slot_blocks = call.buffer<const uint>(1);
  const auto* block_keys = call.buffer<const uint64_t>(2);
  const auto* voxels = call.buffer<const TsdfVoxel>(3);
  auto* status = call.buffer<uint>(4);
  auto* order = call.buffer<uint>(5);
  auto* edge_keys = call.buffer<uint64_t>(6);
  auto* points = call.buffer<float>(7);
  auto* colors = call.buffer<uint>(8);
  for_each_item(call, [&](uint cell) {
    if (cell < params.count)
      tsdf_mesh_cell(keys, slot_blocks, block_keys, voxels, status, order, edge_keys, points,
                     colors, cell, params);
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
  registry.add("tsdf_range", range);
  registry.add("tsdf_mesh", mesh);
  registry.add("tsdf_band", band);
}

}  // namespace kartograf::kernels
