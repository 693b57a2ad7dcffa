// CPU wrapper of kernels/region_grow/region_grow.h.
#include "kernels/region_grow/region_grow_cpu.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <vector>

#include "compute/cpu/cpu_kernel.hpp"

namespace kartograf::kernels {

namespace {

// Marks pixels without a point or a colour in the label image, so that one read of a neighbour's
// label tells both whether it is taken and whether it is valid; unmarked afterwards.
constexpr uint kInvalid = KG_NO_LABEL - 1;

struct Tile {
  int x0, y0, x1, y1;
};

Tile tile_bounds(const RegionGrowParams& params, uint t) {
  const int x0 = static_cast<int>((t % params.tiles_x) * params.tile_size);
  const int y0 = static_cast<int>((t / params.tiles_x) * params.tile_size);
  return {x0, y0, std::min(static_cast<int>(params.width), x0 + static_cast<int>(params.tile_size)),
          std::min(static_cast<int>(params.height), y0 + static_cast<int>(params.tile_size))};
}

void mark_invalid_pixels(const RegionGrowArrays& a, uint width, const Tile& tile) {
  for (int y = tile.y0; y < tile.y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    for (int x = tile.x0; x < tile.x1; ++x) {
      a.labels[row + x] =
          region_grow_valid(a.lab[row + x].valid, a.points[row + x]) ? KG_NO_LABEL : kInvalid;
    }
  }
}

void unmark_invalid_pixels(const RegionGrowArrays& a, uint width, const Tile& tile) {
  for (int y = tile.y0; y < tile.y1; ++y) {
    uint* row = a.labels + static_cast<std::size_t>(y) * width;
    for (int x = tile.x0; x < tile.x1; ++x) {
      if (row[x] == kInvalid) row[x] = KG_NO_LABEL;
    }
  }
}

// One segment as it grows.
struct Segment {
  std::int64_t sum_l = 0, sum_a = 0, sum_b = 0, count = 0;
  RegionMoments moments = region_moments_zero();
};

// Grows the segment seeded at `seed` with the paper's stack, labelling it `id`. Wide: an integer
// type that holds (T n)^2 for the tile's pixel count n. (Parameters and tile by value: stores to
// the labels cannot alias them. Inlined into the seed loop: a call per segment with these
// arguments by value made the CPU's growing ~10 % slower.)
template <class Wide>
[[gnu::always_inline]] inline Segment grow_segment(const RegionGrowParams params,
                                                   const RegionGrowArrays a, const Tile tile,
                                                   const std::array<std::int32_t, 8> offsets,
                                                   uint seed, uint id, std::vector<uint>& stack) {
  const Wide threshold_sq = static_cast<Wide>(params.threshold_code) * params.threshold_code;
  Segment s;
  stack.clear();
  stack.push_back(seed);
  while (!stack.empty()) {
    const uint pixel = stack.back();
    stack.pop_back();
    if (a.labels[pixel] != KG_NO_LABEL) continue;
    const LabCode4& c = a.lab[pixel];
    if (!region_grow_joins(s.count, s.sum_l, s.sum_a, s.sum_b, c.l, c.a, c.b, threshold_sq)) {
      continue;
    }
    a.labels[pixel] = id;
    ++s.count;
    s.sum_l += c.l, s.sum_a += c.a, s.sum_b += c.b;
    if (params.measure != 0) s.moments = region_moments_add(s.moments, a.points[pixel], params);
    const int x = static_cast<int>(pixel % params.width);
    const int y = static_cast<int>(pixel / params.width);
    const double depth = a.points[pixel].z;
    const auto push = [&](uint neighbour) {
      if (a.labels[neighbour] != KG_NO_LABEL) return;
      if (region_grow_depth_breaks(depth, a.points[neighbour].z, params.depth_ratio)) return;
      stack.push_back(neighbour);
    };
    if (x > tile.x0 && y > tile.y0 && x + 1 < tile.x1 && y + 1 < tile.y1) {  // all 8 inside
      for (int k = 0; k < 8; ++k) push(pixel + offsets[k]);
    } else {
      for (int k = 0; k < 8; ++k) {
        const int nx = x + region_grow_neighbour_dx(k), ny = y + region_grow_neighbour_dy(k);
        if (nx >= tile.x0 && ny >= tile.y0 && nx < tile.x1 && ny < tile.y1)
          push(pixel + offsets[k]);
      }
    }
  }
  return s;
}

// Grows every segment of tile t, numbering them from 0; returns their number.
template <class Wide>
uint grow_tile(const RegionGrowParams params, const RegionGrowArrays a, uint t,
               std::vector<uint>& stack) {
  const Tile tile = tile_bounds(params, t);
  const int width = static_cast<int>(params.width);
  std::array<std::int32_t, 8> offsets;
  for (int k = 0; k < 8; ++k) {
    offsets[k] = region_grow_neighbour_dy(k) * width + region_grow_neighbour_dx(k);
  }
  mark_invalid_pixels(a, params.width, tile);
  uint next = 0;
  for (int seed_y = tile.y0; seed_y < tile.y1; ++seed_y) {
    for (int seed_x = tile.x0; seed_x < tile.x1; ++seed_x) {
      const uint seed = static_cast<uint>(seed_y) * params.width + static_cast<uint>(seed_x);
      if (a.labels[seed] != KG_NO_LABEL) continue;
      const uint id = next++;
      const Segment s = grow_segment<Wide>(params, a, tile, offsets, seed, id, stack);
      if (params.measure == 0) continue;
      double* slot = a.slots + region_statistics_slot(t, id, params);
      for (uint v = 0; v < KG_REGION_GROW_STATISTICS; ++v) {
        slot[v] = region_statistic(v, s.count, s.sum_l, s.sum_a, s.sum_b, s.moments);
      }
    }
  }
  unmark_invalid_pixels(a, params.width, tile);
  return next;
}

}  // namespace

void region_grow_tiles_cpu(const RegionGrowParams& params, const RegionGrowArrays& arrays) {
  const std::size_t tile = params.tile_size;
  // (T n)^2 < 2^63 for T <= 64000 codes and n <= 4096 pixels.
  const bool narrow = tile * tile <= 4096;
  const std::size_t pixel_count = std::size_t{params.width} * params.height;
  compute::detail::for_each_chunk(
      params.tile_count, params.tile_count > 1 ? pixel_count : 0,
      [&](std::size_t begin, std::size_t end, std::size_t) {
        std::vector<uint> stack;
        stack.reserve(narrow ? 8 * tile * tile + 1 : 1 << 16);
        for (std::size_t t = begin; t < end; ++t) {
          const uint index = static_cast<uint>(t);
          arrays.tile_counts[t] = narrow ? grow_tile<std::int64_t>(params, arrays, index, stack)
                                         : grow_tile<__int128>(params, arrays, index, stack);
        }
      });
}

uint region_grow_scan_cpu(const RegionGrowParams& params, uint* tile_counts) {
  uint running = 0;
  for (uint t = 0; t < params.padded_tile_count; ++t) {
    const uint value = tile_counts[t];
    tile_counts[t] = running;
    running += value;
  }
  return running;
}

void region_grow_offsets_cpu(const RegionGrowParams& params, uint* labels,
                             const uint* tile_offsets) {
  const uint width = params.width;
  compute::detail::for_each_chunk(
      params.height, std::size_t{width} * params.height,
      [&](std::size_t first, std::size_t last, std::size_t) {
        for (std::size_t y = first; y < last; ++y) {
          uint* row = labels + y * width;
          const uint* offsets = tile_offsets + (y / params.tile_size) * params.tiles_x;
          for (uint tx = 0; tx < params.tiles_x; ++tx) {
            const uint offset = offsets[tx];
            if (offset == 0) continue;
            const uint x1 = std::min(width, (tx + 1) * params.tile_size);
            for (uint x = tx * params.tile_size; x < x1; ++x) {
              if (row[x] != KG_NO_LABEL) row[x] += offset;
            }
          }
        }
      });
}

void region_grow_statistics_cpu(const RegionGrowParams& params, const uint* tile_offsets,
                                uint total, const double* slots, double* statistics) {
  for (uint t = 0; t < params.tile_count; ++t) {
    const uint first = tile_offsets[t];
    const uint end = t + 1 < params.tile_count ? tile_offsets[t + 1] : total;
    std::memcpy(statistics + std::size_t{first} * KG_REGION_GROW_STATISTICS,
                slots + region_statistics_slot(t, 0, params),
                std::size_t{end - first} * KG_REGION_GROW_STATISTICS * sizeof(double));
  }
}

namespace {

void region_grow_tiles(const compute::detail::CpuDispatch& call) {
  // The device's stacks (binding 4) and overflow counter are not needed: the CPU's stacks grow.
  region_grow_tiles_cpu(call.params_as<RegionGrowParams>(),
                        {call.buffer<const LabCode4>(0), call.buffer<const float4>(1),
                         call.buffer<uint>(2), call.buffer<uint>(3), call.buffer<double>(6)});
}

void region_grow_scan(const compute::detail::CpuDispatch& call) {
  call.buffer<uint>(1)[KG_REGION_GROW_SEGMENT_COUNT] =
      region_grow_scan_cpu(call.params_as<RegionGrowParams>(), call.buffer<uint>(0));
}

void region_grow_offsets(const compute::detail::CpuDispatch& call) {
  region_grow_offsets_cpu(call.params_as<RegionGrowParams>(), call.buffer<uint>(0),
                          call.buffer<const uint>(1));
}

void region_grow_statistics(const compute::detail::CpuDispatch& call) {
  region_grow_statistics_cpu(call.params_as<RegionGrowParams>(), call.buffer<const uint>(0),
                             call.buffer<const uint>(1)[KG_REGION_GROW_SEGMENT_COUNT],
                             call.buffer<const double>(2), call.buffer<double>(3));
}

}  // namespace

void register_region_grow_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("region_grow_tiles", region_grow_tiles);
  registry.add("region_grow_scan", region_grow_scan);
  registry.add("region_grow_offsets", region_grow_offsets);
  registry.add("region_grow_statistics", region_grow_statistics);
}

}  // namespace kartograf::kernels
