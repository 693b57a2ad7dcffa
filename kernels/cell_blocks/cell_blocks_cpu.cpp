// CPU wrapper of kernels/cell_blocks/cell_blocks.h: the rule's block loop with the sums taken in
// four lanes at once (the same float sums, in the same order, per lane), the colour read as bytes
// and the jumps counted on each row's depths gathered as the sums go (vector code); the blocks in
// chunks over the threads.
#include <cstring>

#include "compute/cpu/cpu_kernel.hpp"
#include "compute/cpu/lanes.hpp"
#include "kernels/cell_blocks/cell_blocks.h"

namespace kartograf::kernels {

namespace {

using compute::detail::Lanes;

struct BlockOutputs {
  float* sums;
  uint* counts;
  uint* masks;
};

// Jumps between `depths` and `others` (n each; NaN: no depth, no jump), vector code.
uint count_jumps(const float* depths, const float* others, uint n, const CellBlocksParams& p) {
  uint count = 0;
  for (uint k = 0; k < n; ++k) count += cell_jump_count(depths[k], others[k], p);
  return count;
}

void measure_block(const float4* points, const std::uint8_t* colours, uint block,
                   const CellBlocksParams& p, const BlockOutputs& out) {
  const CellBlockRect r = cell_block_rect(block, p);
  const float4 reference = cell_block_reference(points, r, p);
  const Lanes origin{reference.x, reference.y, reference.z, 0.0f};
  // With d = (dx, dy, dz, 1): `first` sums d (the count in its last lane), `by_x` .. `by_z` sum
  // d dx .. d dz.
  Lanes first{}, by_x{}, by_y{}, by_z{};
  uint red = 0, green = 0, blue = 0, inside = 0, edge = 0;
  // The validity bits in a local array (stores through `out` could alias the points).
  uint mask[32] = {};  // p.mask_words <= 32: blocks of at most 32 x 32 pixels
  // cell_row_jumps' counts from the rows' depths gathered as the sums go: depth[0] is the pixel
  // left of the block in its cell (NaN where the block starts its cell), depth[1..n] the row's;
  // `above` the row above's, where there is one in the cell.
  const uint n = r.x1 - r.x0;
  float depth[33], above[32];
  bool has_above = r.y0 > r.cell_y0;
  for (uint k = 0; has_above && k < n; ++k) above[k] = points[(r.y0 - 1) * p.width + r.x0 + k].z;
  for (uint y = r.y0; y < r.y1; ++y) {
    const std::size_t row = std::size_t{y} * p.width;
    // NaN also for an empty block (past the image's edge), whose depth[1] is never written.
    depth[0] = r.x0 > r.cell_x0 && n > 0 ? points[row + r.x0 - 1].z : KG_NAN;
    std::uint64_t row_bits = 0;  // at most 32
    for (uint x = r.x0; x < r.x1; ++x) {
      const float4& q = points[row + x];
      depth[1 + x - r.x0] = q.z;
      if (kg_isnan(q.x)) continue;
      row_bits |= std::uint64_t{1} << (x - r.x0);
      Lanes d;
      std::memcpy(&d, &q, sizeof d);
      d = d - origin;
      d[3] = 1.0f;
      first += d;
      by_x += d * d[0], by_y += d * d[1], by_z += d * d[2];
      const std::uint8_t* rgb = colours + 3 * (row + x);
      red += rgb[0], green += rgb[1], blue += rgb[2];
    }
    const uint start = (y - r.y0) * p.block_size;  // the row's first bit
    mask[start / 32] |= static_cast<uint>(row_bits << (start % 32));
    if (start % 32 + p.block_size > 32)
      mask[start / 32 + 1] |= static_cast<uint>(row_bits >> (32 - start % 32));
    inside += count_jumps(depth + 2, depth + 1, n > 0 ? n - 1 : 0, p);
    edge += cell_jump_count(depth[1], depth[0], p);
    if (has_above) (y > r.y0 ? inside : edge) += count_jumps(depth + 1, above, n, p);
    std::copy_n(depth + 1, n, above);
    has_above = true;
  }
  const float values[KG_CELL_BLOCK_SUMS] = {reference.x, reference.y, reference.z, first[0],
                                            first[1],    first[2],    by_x[0],     by_x[1],
                                            by_x[2],     by_y[1],     by_y[2],     by_z[2]};
  std::copy_n(values, KG_CELL_BLOCK_SUMS, out.sums + std::size_t{block} * KG_CELL_BLOCK_SUMS);
  const uint counts[KG_CELL_BLOCK_COUNTS] = {
      static_cast<uint>(first[3]), red, green, blue, inside, edge};
  std::copy_n(counts, KG_CELL_BLOCK_COUNTS, out.counts + std::size_t{block} * KG_CELL_BLOCK_COUNTS);
  std::copy_n(mask, p.mask_words, out.masks + std::size_t{block} * p.mask_words);
}

void cell_blocks(const compute::detail::CpuDispatch& call) {
  const auto p = call.params_as<CellBlocksParams>();
  const auto* points = call.buffer<const float4>(0);
  const auto* colours = call.buffer<const std::uint8_t>(1);
  const BlockOutputs out{call.buffer<float>(2), call.buffer<uint>(3), call.buffer<uint>(4)};
  compute::detail::for_each_chunk(p.block_count, std::size_t{p.width} * p.height,
                                  [&](std::size_t begin, std::size_t end, std::size_t) {
                                    for (std::size_t b = begin; b < end; ++b) {
                                      measure_block(points, colours, static_cast<uint>(b), p, out);
                                    }
                                  });
}

}  // namespace

void register_cell_blocks_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("cell_blocks", cell_blocks);
}

}  // namespace kartograf::kernels
