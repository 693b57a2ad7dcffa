// CPU wrapper of kernels/cell_blocks/cell_blocks.h: the rule's block loop four pixels at a time,
// in vector code: their x, y and z, validity, colour bytes and depth jumps (against the pixels
// left of and above them) in lanes, each lane summing its own pixels and the lanes added once per
// block; the blocks in chunks over the threads. Blocks eight pixels wide take the AVX2 form
// (cell_blocks_wide.hpp) where the processor has it: the pass 0.99 -> 0.69 ms on a 7-Scenes
// frame (one thread, with the cells' sums after it).
#include <algorithm>
#include <array>
#include <cstring>

#include "compute/cpu/cpu_kernel.hpp"
#include "compute/cpu/lanes.hpp"
#include "kernels/cell_blocks/cell_blocks.h"
#include "kernels/cell_blocks/cell_blocks_wide.hpp"

namespace kartograf::kernels {

namespace {

using compute::detail::LaneMask;
using compute::detail::Lanes;
using compute::detail::load_xyz;
using compute::detail::select;
using compute::detail::XyzLanes;

struct BlockOutputs {
  float* sums;
  uint* counts;
  uint* masks;
};

// Per lane: cell_depth_jump(a, b) (-1 where it holds, else 0), the same float operations in
// vector form (the rule called lane by lane cost the block pass 240 million instructions on the
// 7-Scenes frames against 182); the tests hold the counts to the rule exactly.
LaneMask jump_lanes(Lanes a, Lanes b, const CellBlocksParams& p) {
  using compute::detail::max_of;
  using compute::detail::min_of;
  const Lanes z = min_of(a, b);
  const Lanes relative = max_of(compute::detail::splat(p.max_depth_jump), p.jump_per_z2 * z);
  const Lanes magnitude = reinterpret_cast<Lanes>(reinterpret_cast<LaneMask>(a - b) & 0x7fffffff);
  return magnitude > z * relative;
}

// A block's depth jumps (cell_row_jumps' counts), four pixels at a time: per lane, those within
// the block and those with the blocks left of and above it in its cell. Negative counts (a mask
// lane is -1).
struct JumpLanes {
  LaneMask inside{}, edge{};

  // Group z (four pixels of a row) against `left` (the pixels one to the left; lane 0 lies in the
  // block on the left when `first`, NaN where that is another cell's) and `above` (the row above's;
  // another block's when `top`, NaN where that is another cell's).
  void add(Lanes z, Lanes left, Lanes above, bool first, bool top, const CellBlocksParams& p) {
    const LaneMask horizontal = jump_lanes(z, left, p);
    const LaneMask lane_zero{-1, 0, 0, 0};
    inside += first ? horizontal & ~lane_zero : horizontal;
    if (first) edge += horizontal & lane_zero;
    (top ? edge : inside) += jump_lanes(z, above, p);
  }
};

uint lane_total(LaneMask v) {
  return static_cast<uint>(-(v[0] + v[1] + v[2] + v[3]));
}

// The sums of one block, four columns at a time: lane j sums the block's columns j, j + 4, ...
// (row by row), and the lanes are added at the end. A different order from the rule's (one pixel
// after the other), so the sums differ from a device's by rounding (tests/cell_blocks_test.cpp's
// tolerance); the counts, colours, jumps and bits are exact. `count` counts down (a valid lane
// is -1).
struct BlockLanes {
  Lanes x{}, y{}, z{}, xx{}, xy{}, xz{}, yy{}, yz{}, zz{};
  LaneMask count{};

  void add(const XyzLanes& p, const Lanes& origin, LaneMask valid) {
    const Lanes zero{};
    const Lanes dx = select(valid, p.x - origin[0], zero);
    const Lanes dy = select(valid, p.y - origin[1], zero);
    const Lanes dz = select(valid, p.z - origin[2], zero);
    count += valid;
    x += dx, y += dy, z += dz;
    xx += dx * dx, xy += dx * dy, xz += dx * dz;
    yy += dy * dy, yz += dy * dz, zz += dz * dz;
  }
};

float lane_sum(const Lanes& v) {
  return (v[0] + v[1]) + (v[2] + v[3]);
}

// Bit j of the result: lane j of the mask is set.
std::uint32_t mask_bits(LaneMask valid) {
  const LaneMask weights{1, 2, 4, 8};
  const LaneMask bits = valid & weights;
  return static_cast<std::uint32_t>(bits[0] | bits[1] | bits[2] | bits[3]);
}

// The colour sums of a block's valid pixels, four pixels (twelve bytes) at a time: lane b of the
// two halves sums byte b of the groups of four (at most 32 x 8 groups of 255 in a block: 16 bits
// are enough). Their red, green and blue are bytes 0, 3, 6, 9; 1, 4, 7, 10; 2, 5, 8, 11.
struct ColourLanes {
  using Bytes = std::uint8_t __attribute__((vector_size(8)));
  using Shorts = std::uint16_t __attribute__((vector_size(16)));
  Shorts low{}, high{};  // bytes 0-7 and 8-11 (and four unused)

  // The pixels of `valid` (bit j: pixel j) among the `count` (<= 4) from `rgb`.
  void add(const std::uint8_t* rgb, std::uint32_t valid, uint count) {
    Bytes first{}, second{};
    if (count == 4) {  // fixed sizes: no call, no byte loop
      std::memcpy(&first, rgb, 8), std::memcpy(&second, rgb + 8, 4);
    } else {
      for (uint b = 0; b < 3 * count; ++b) (b < 8 ? first[b] : second[b - 8]) = rgb[b];
    }
    low += __builtin_convertvector(first, Shorts) & mask(valid, Shorts{1, 1, 1, 2, 2, 2, 4, 4});
    high += __builtin_convertvector(second, Shorts) & mask(valid, Shorts{4, 8, 8, 8, 0, 0, 0, 0});
  }
  std::array<uint, 3> sums() const {
    return {uint{low[0]} + low[3] + low[6] + high[1], uint{low[1]} + low[4] + low[7] + high[2],
            uint{low[2]} + low[5] + high[0] + high[3]};
  }

 private:
  // All ones on the bytes of the pixels set in `valid`; `pixel_bit`: each byte's pixel's bit.
  static Shorts mask(std::uint32_t valid, Shorts pixel_bit) {
    return reinterpret_cast<Shorts>(((Shorts{} + static_cast<std::uint16_t>(valid)) & pixel_bit) !=
                                    0);
  }
};

// What a block gathers as its rows go by.
struct BlockState {
  BlockLanes sums;
  ColourLanes colour;
  JumpLanes jumps;
  // Per group of four of the block's columns: the row above's depths (NaN: none in the cell).
  Lanes above[8];
  uint mask[32] = {};  // validity bits: p.mask_words <= 32 (blocks of at most 32 x 32 pixels)
};

// The block's row y, four pixels at a time (NaN lanes past the block's width n).
void measure_row(const float4* points, const std::uint8_t* colours, const CellBlockRect& r, uint y,
                 const CellBlocksParams& p, const Lanes& origin, BlockState& block) {
  const std::size_t row = std::size_t{y} * p.width;
  const uint n = r.x1 - r.x0;
  // The pixel left of the block, where it is in the block's cell.
  Lanes left_of_group =
      compute::detail::splat(r.x0 > r.cell_x0 ? points[row + r.x0 - 1].z : KG_NAN);
  const bool top = y == r.y0;
  std::uint64_t bits = 0;  // at most 32
  for (uint k = 0; k < n; k += 4) {
    const XyzLanes q = load_xyz(&points[row + r.x0 + k].x, static_cast<int>(std::min(4u, n - k)));
    const LaneMask valid = q.x == q.x;  // false for NaN, and past the row's end
    block.sums.add(q, origin, valid);
    const std::uint32_t group_bits = mask_bits(valid);
    block.colour.add(colours + 3 * (row + r.x0 + k), group_bits, std::min(4u, n - k));
    bits |= std::uint64_t{group_bits} << k;
    const Lanes left = compute::detail::shift_in(left_of_group, q.z);
    block.jumps.add(q.z, left, block.above[k / 4], k == 0, top, p);
    block.above[k / 4] = q.z;
    left_of_group = q.z;
  }
  const uint start = (y - r.y0) * p.block_size;  // the row's first bit
  block.mask[start / 32] |= static_cast<uint>(bits << (start % 32));
  if (start % 32 + p.block_size > 32)
    block.mask[start / 32 + 1] |= static_cast<uint>(bits >> (32 - start % 32));
}

// Writes a block's results where cell_blocks.h's outputs keep them.
void store_block(const BlockOutputs& out, uint block, const float4& reference,
                 const std::array<float, 9>& sums,
                 const std::array<uint, KG_CELL_BLOCK_COUNTS>& counts, const uint* mask,
                 uint mask_words) {
  float* block_sums = out.sums + std::size_t{block} * KG_CELL_BLOCK_SUMS;
  block_sums[0] = reference.x, block_sums[1] = reference.y, block_sums[2] = reference.z;
  std::copy(sums.begin(), sums.end(), block_sums + 3);
  std::copy(counts.begin(), counts.end(), out.counts + std::size_t{block} * KG_CELL_BLOCK_COUNTS);
  std::copy_n(mask, mask_words, out.masks + std::size_t{block} * mask_words);
}

void measure_block(const float4* points, const std::uint8_t* colours, uint block,
                   const CellBlocksParams& p, const BlockOutputs& out) {
  const CellBlockRect r = cell_block_rect(block, p);
  const float4 reference = cell_block_reference(points, r, p);
  const Lanes origin{reference.x, reference.y, reference.z, 0.0f};
  BlockState state;
  const uint n = r.x1 - r.x0;
  for (uint k = 0; k < n; k += 4) {
    const bool in_cell = r.y0 > r.cell_y0;
    state.above[k / 4] = in_cell ? load_xyz(&points[(r.y0 - 1) * p.width + r.x0 + k].x,
                                            static_cast<int>(std::min(4u, n - k)))
                                       .z
                                 : compute::detail::splat(KG_NAN);
  }
  for (uint y = r.y0; y < r.y1; ++y) measure_row(points, colours, r, y, p, origin, state);
  const BlockLanes& s = state.sums;
  const std::array<uint, 3> colour = state.colour.sums();
  store_block(out, block, reference,
              {lane_sum(s.x), lane_sum(s.y), lane_sum(s.z), lane_sum(s.xx), lane_sum(s.xy),
               lane_sum(s.xz), lane_sum(s.yy), lane_sum(s.yz), lane_sum(s.zz)},
              {lane_total(s.count), colour[0], colour[1], colour[2], lane_total(state.jumps.inside),
               lane_total(state.jumps.edge)},
              state.mask, p.mask_words);
}

using BlockRange = void (*)(const float4*, const std::uint8_t*, std::size_t, std::size_t,
                            const CellBlocksParams&, const BlockOutputs&);

void measure_blocks(const float4* points, const std::uint8_t* colours, std::size_t begin,
                    std::size_t end, const CellBlocksParams& p, const BlockOutputs& out) {
  for (std::size_t b = begin; b < end; ++b)
    measure_block(points, colours, static_cast<uint>(b), p, out);
}

#if KARTOGRAF_WIDE_LANES
// Blocks eight pixels wide in AVX2 (cell_blocks_wide.hpp), the rest (cut by the image's right
// edge) as above.
KG_WIDE_TARGET void measure_blocks_wide(const float4* points, const std::uint8_t* colours,
                                        std::size_t begin, std::size_t end,
                                        const CellBlocksParams& p, const BlockOutputs& out) {
  for (std::size_t b = begin; b < end; ++b) {
    const auto block = static_cast<uint>(b);
    const CellBlockRect r = cell_block_rect(block, p);
    if (r.x1 - r.x0 != 8u) {
      measure_block(points, colours, block, p, out);
      continue;
    }
    const float4 reference = cell_block_reference(points, r, p);
    const MeasuredBlock m = wide::measure_block(points, colours, r, p, reference);
    const uint mask[2] = {static_cast<uint>(m.mask), static_cast<uint>(m.mask >> 32)};
    store_block(out, block, reference, m.sums, m.counts, mask, p.mask_words);
  }
}
#endif

// The wide code where the processor has it and the blocks are eight pixels a side.
BlockRange block_range_code([[maybe_unused]] const CellBlocksParams& p) {
#if KARTOGRAF_WIDE_LANES
  if (p.block_size == 8u && compute::detail::wide_lanes_enabled()) return measure_blocks_wide;
#endif
  return measure_blocks;
}

void cell_blocks(const compute::detail::CpuDispatch& call) {
  const auto p = call.params_as<CellBlocksParams>();
  const auto* points = call.buffer<const float4>(0);
  const auto* colours = call.buffer<const std::uint8_t>(1);
  const BlockOutputs out{call.buffer<float>(2), call.buffer<uint>(3), call.buffer<uint>(4)};
  const BlockRange measure = block_range_code(p);
  compute::detail::for_each_chunk(p.block_count, std::size_t{p.width} * p.height,
                                  [&](std::size_t begin, std::size_t end, std::size_t) {
                                    measure(points, colours, begin, end, p, out);
                                  });
}

}  // namespace

void register_cell_blocks_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("cell_blocks", cell_blocks);
}

}  // namespace kartograf::kernels
