#pragma once
// The block pass of cell_blocks_cpu.cpp in AVX2 (compute/cpu/wide_lanes.hpp), for blocks eight
// pixels wide that the image does not cut (all of a 640x480 frame's with 16-pixel cells): a block
// row in one step, its validity and depth jumps as bit masks counted with popcount, its colour
// bytes summed in 16-bit lanes. About a third of the four-lane code's instructions per pixel
// (where the pass spent most of its time on the transposes, the colour and the jump counts).
// Same results as the four-lane code but for the sums' rounding (their lanes add in another
// order); tests/cell_blocks_test.cpp holds both to the rule.
#include <array>
#include <cstdint>

#include "compute/cpu/wide_lanes.hpp"
#include "kernels/cell_blocks/cell_blocks.h"

namespace kartograf::kernels {

// What a block gives, as cell_blocks.h's outputs lay it out.
struct MeasuredBlock {
  std::array<float, 9> sums{};  // sum d, then sum d d^T's upper triangle
  std::array<uint, KG_CELL_BLOCK_COUNTS> counts{};
  std::uint64_t mask = 0;  // validity bits, row by row (eight a row)
};

#if KARTOGRAF_WIDE_LANES

namespace wide {

using compute::detail::HalfBytes;
using compute::detail::WideLanes;
using compute::detail::WideMask;
using compute::detail::WideShorts;

struct BlockState {
  WideLanes x{}, y{}, z{}, xx{}, xy{}, xz{}, yy{}, yz{}, zz{};
  WideShorts colour_low{}, colour_high{};  // a row's colour bytes 0-15 and 16-23
  WideLanes above{};                       // the row above's depths (NaN: none in the cell)
  std::uint64_t mask = 0;
  uint count = 0, inside = 0, edge = 0;
};

// Bit j: cell_depth_jump(a[j], b[j]), with the rule's float operations.
KG_WIDE_TARGET inline std::uint32_t jump_bits(WideLanes a, WideLanes b, const CellBlocksParams& p) {
  const WideLanes z = b < a ? b : a;
  const WideLanes scaled = p.jump_per_z2 * z;
  const WideLanes floor = WideLanes{} + p.max_depth_jump;
  const WideLanes relative = floor < scaled ? scaled : floor;
  const WideLanes magnitude =
      reinterpret_cast<WideLanes>(reinterpret_cast<WideMask>(a - b) & 0x7fffffff);
  return compute::detail::wide_mask_bits(magnitude > z * relative);
}

// The eight pixels' colour bytes (24) where their bit in `valid` is set, added to the lanes.
KG_WIDE_TARGET inline void add_colours(const std::uint8_t* rgb, std::uint32_t valid,
                                       BlockState& s) {
  HalfBytes low;
  __builtin_memcpy(&low, rgb, 16);
  // The last eight bytes through a 64-bit word: a 16-byte load of a half-written vector would
  // wait for the two stores to retire (no store forwarding), which cost the pass a third.
  std::uint64_t rest;
  __builtin_memcpy(&rest, rgb + 16, 8);
  using HalfWords = std::uint64_t __attribute__((vector_size(16)));
  HalfBytes high = reinterpret_cast<HalfBytes>(HalfWords{rest, 0});
  const HalfBytes low_pixel{1, 1, 1, 2, 2, 2, 4, 4, 4, 8, 8, 8, 16, 16, 16, 32};
  const HalfBytes high_pixel{32, 32, 64, 64, 64, 128, 128, 128, 0, 0, 0, 0, 0, 0, 0, 0};
  const auto bits = static_cast<std::uint8_t>(valid);
  low &= reinterpret_cast<HalfBytes>((low_pixel & bits) != 0);
  high &= reinterpret_cast<HalfBytes>((high_pixel & bits) != 0);
  s.colour_low += __builtin_convertvector(low, WideShorts);
  s.colour_high += __builtin_convertvector(high, WideShorts);
}

KG_WIDE_TARGET inline void measure_row(const float4* points, const std::uint8_t* colours,
                                       const CellBlockRect& r, uint y, const CellBlocksParams& p,
                                       const float4& reference, BlockState& s) {
  const std::size_t first = std::size_t{y} * p.width + r.x0;
  const compute::detail::WideXyz q = compute::detail::load_eight_xyz(&points[first].x);
  const WideMask valid = q.x == q.x;  // false for NaN
  const std::uint32_t bits = compute::detail::wide_mask_bits(valid);
  const WideLanes none{};
  const WideLanes dx = valid ? q.x - reference.x : none;
  const WideLanes dy = valid ? q.y - reference.y : none;
  const WideLanes dz = valid ? q.z - reference.z : none;
  s.x += dx, s.y += dy, s.z += dz;
  s.xx += dx * dx, s.xy += dx * dy, s.xz += dx * dz;
  s.yy += dy * dy, s.yz += dy * dz, s.zz += dz * dz;
  s.count += static_cast<uint>(__builtin_popcount(bits));
  s.mask |= std::uint64_t{bits} << ((y - r.y0) * 8);
  add_colours(colours + 3 * first, bits, s);
  // Lane 0's left neighbour is in the block on the left when that is in the same cell.
  const float left = r.x0 > r.cell_x0 ? points[first - 1].z : KG_NAN;
  const std::uint32_t horizontal = jump_bits(q.z, compute::detail::wide_shift_in(left, q.z), p);
  s.inside += static_cast<uint>(__builtin_popcount(horizontal & 0xfeu));
  s.edge += horizontal & 1u;
  const auto vertical = static_cast<uint>(__builtin_popcount(jump_bits(q.z, s.above, p)));
  (y == r.y0 ? s.edge : s.inside) += vertical;
  s.above = q.z;
}

// The red, green and blue sums from the colour lanes (byte b of a row is channel b % 3).
KG_WIDE_TARGET inline std::array<uint, 3> colour_sums(const BlockState& s) {
  std::array<uint, 3> rgb{};
  for (int b = 0; b < 16; ++b) rgb[b % 3] += s.colour_low[b];
  for (int b = 0; b < 8; ++b) rgb[(16 + b) % 3] += s.colour_high[b];
  return rgb;
}

// Block `r` (eight pixels wide, any rows) about `reference` (its first valid point).
KG_WIDE_TARGET inline MeasuredBlock measure_block(const float4* points, const std::uint8_t* colours,
                                                  const CellBlockRect& r, const CellBlocksParams& p,
                                                  const float4& reference) {
  BlockState s;
  s.above = r.y0 > r.cell_y0
                ? compute::detail::load_eight_xyz(&points[(r.y0 - 1) * p.width + r.x0].x).z
                : WideLanes{} + KG_NAN;
  for (uint y = r.y0; y < r.y1; ++y) measure_row(points, colours, r, y, p, reference, s);
  using compute::detail::wide_sum;
  MeasuredBlock out;
  out.sums = {wide_sum(s.x),  wide_sum(s.y),  wide_sum(s.z),  wide_sum(s.xx), wide_sum(s.xy),
              wide_sum(s.xz), wide_sum(s.yy), wide_sum(s.yz), wide_sum(s.zz)};
  const std::array<uint, 3> rgb = colour_sums(s);
  out.counts = {s.count, rgb[0], rgb[1], rgb[2], s.inside, s.edge};
  out.mask = s.mask;
  return out;
}

}  // namespace wide

#endif

}  // namespace kartograf::kernels
