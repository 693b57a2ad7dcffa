#pragma once
// The block pass of cell_blocks_cpu.cpp in AVX2 (compute/cpu/wide_lanes.hpp), for blocks eight
// pixels wide that the image does not cut (all of a 640x480 frame's with 16-pixel cells): a block
// row in one step, its validity and depth jumps as bit masks counted with popcount, its colour
// bytes summed per channel by psadbw. About a third of the four-lane code's instructions per pixel
// (where the pass spent most of its time on the transposes, the colour and the jump counts).
// Same results as the four-lane code but for the sums' rounding (their lanes add in another
// order); tests/cell_blocks_test.cpp holds both to the rule.
#include <array>
#include <cstdint>

#include "compute/cpu/wide_lanes.hpp"
#if KARTOGRAF_WIDE_LANES
#include <immintrin.h>
#endif
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

struct BlockState {
  WideLanes x{}, y{}, z{}, xx{}, xy{}, xz{}, yy{}, yz{}, zz{};
  __m128i red_green{}, blue{};  // the colour sums, 64-bit lanes: red, green; blue, 0
  WideLanes above{};            // the row above's depths (NaN: none in the cell)
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

// The eight pixels' colour bytes (24) where their bit in `valid` is set, added to the sums: the
// bytes sorted by channel (R0..R7 G0..G7 and B0..B7) with two byte shuffles each, masked per
// pixel, and each channel's eight bytes summed by psadbw into a 64-bit lane.
KG_WIDE_TARGET inline void add_colours(const std::uint8_t* rgb, std::uint32_t valid,
                                       BlockState& s) {
  const __m128i low = _mm_loadu_si128(reinterpret_cast<const __m128i*>(rgb));
  const __m128i high = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(rgb + 16));
  constexpr char z = -128;  // a shuffle index that gives 0
  const __m128i red_green = _mm_or_si128(
      _mm_shuffle_epi8(low, _mm_setr_epi8(0, 3, 6, 9, 12, 15, z, z, 1, 4, 7, 10, 13, z, z, z)),
      _mm_shuffle_epi8(high, _mm_setr_epi8(z, z, z, z, z, z, 2, 5, z, z, z, z, z, 0, 3, 6)));
  const __m128i blue = _mm_or_si128(
      _mm_shuffle_epi8(low, _mm_setr_epi8(2, 5, 8, 11, 14, z, z, z, z, z, z, z, z, z, z, z)),
      _mm_shuffle_epi8(high, _mm_setr_epi8(z, z, z, z, z, 1, 4, 7, z, z, z, z, z, z, z, z)));
  const __m128i pixel_bit = _mm_setr_epi8(1, 2, 4, 8, 16, 32, 64, z, 1, 2, 4, 8, 16, 32, 64, z);
  const __m128i bits = _mm_set1_epi8(static_cast<char>(valid));
  const __m128i mask = _mm_cmpeq_epi8(_mm_and_si128(bits, pixel_bit), pixel_bit);
  s.red_green = _mm_add_epi64(s.red_green, _mm_sad_epu8(_mm_and_si128(red_green, mask), __m128i{}));
  s.blue = _mm_add_epi64(s.blue, _mm_sad_epu8(_mm_and_si128(blue, mask), __m128i{}));
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

KG_WIDE_TARGET inline std::array<uint, 3> colour_sums(const BlockState& s) {
  return {static_cast<uint>(_mm_cvtsi128_si64(s.red_green)),
          static_cast<uint>(_mm_extract_epi64(s.red_green, 1)),
          static_cast<uint>(_mm_cvtsi128_si64(s.blue))};
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
