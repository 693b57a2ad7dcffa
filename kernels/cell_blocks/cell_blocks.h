// The cells mode's one pass over a frame (src/segmentation/cell_planes.hpp, measure_cells): per
// square block of block_size pixels (a cell is 2 x 2 blocks), its first valid point (row by row),
// the float sums of d and d d^T about that point (d = p - reference), its valid pixels' count and
// colour sums, its depth jumps (within it; with the blocks left of and above it in the same
// cell) and its validity bits. One block per work-item, its pixels in row order: the devices sum
// in the CPU's order (the CPU wrapper takes the same sums four lanes at a time).
#ifndef KARTOGRAF_KERNELS_CELL_BLOCKS_H
#define KARTOGRAF_KERNELS_CELL_BLOCKS_H
#include "shaders/prelude.h"

#define KG_CELL_BLOCKS_LOCAL_X 64

// Per block, floats: [0..2] the reference point, [3..5] sum d, [6..11] sum d d^T upper triangle
// (xx xy xz yy yz zz); all zero when the block has no valid pixel.
#define KG_CELL_BLOCK_SUMS 12u
// Per block, uints: [0] valid pixels, [1..3] red, green, blue sums, [4] jumps within the block,
// [5] jumps with the blocks left of and above it in the same cell.
#define KG_CELL_BLOCK_COUNTS 6u
#define KG_CELL_BLOCK_COUNT 0u
#define KG_CELL_BLOCK_INSIDE_JUMPS 4u
#define KG_CELL_BLOCK_EDGE_JUMPS 5u

KG_RULES_BEGIN

KG_PARAMS_BEGIN(CellBlocksParams)
KG_PARAM(uint, width)
KG_PARAM(uint, height)
KG_PARAM(uint, block_size)       // half a cell
KG_PARAM(uint, blocks_x)         // 2 per cell column (blocks past the image's edge are empty)
KG_PARAM(uint, block_count)      // blocks_x times 2 per cell row
KG_PARAM(uint, mask_words)       // validity words per block: block_size^2 bits, row by row
KG_PARAM(float, max_depth_jump)  // relative to the nearer depth
KG_PARAM(float, jump_per_z2)     // and at least this times z^2
KG_PARAMS_END(CellBlocksParams)

// A jump between neighbouring depths: more than max_depth_jump of the nearer one and more than
// jump_per_z2 z^2 (far away, noise and quantization alone exceed the relative part). False when
// either is NaN (no depth).
KG_INLINE bool cell_depth_jump(float a, float b, CellBlocksParams p) {
  const float z = min(a, b);
  return kg_fabs(a - b) > z * max(p.max_depth_jump, p.jump_per_z2 * z);
}

// Byte `index` of the colour image (RGB, 3 bytes a pixel) read from 32-bit words, little-endian.
KG_INLINE uint cell_colour_byte(KG_BUFFER_PARAM(const uint, colours) uint index) {
  return (colours[index >> 2u] >> ((index & 3u) * 8u)) & 255u;
}

// The block's pixel rectangle [x0, x1) x [y0, y1), cut by the image (empty past its edge).
KG_STRUCT_BEGIN(CellBlockRect)
uint x0;
uint y0;
uint x1;
uint y1;
uint cell_x0;
uint cell_y0;
KG_STRUCT_END(CellBlockRect)

KG_INLINE CellBlockRect cell_block_rect(uint block, CellBlocksParams p) {
  CellBlockRect r;
  const uint bx = block % p.blocks_x, by = block / p.blocks_x;
  r.x0 = min(p.width, bx * p.block_size);
  r.y0 = min(p.height, by * p.block_size);
  r.x1 = min(p.width, r.x0 + p.block_size);
  r.y1 = min(p.height, r.y0 + p.block_size);
  r.cell_x0 = (bx / 2u) * 2u * p.block_size;
  r.cell_y0 = (by / 2u) * 2u * p.block_size;
  return r;
}

KG_STRUCT_BEGIN(CellRowJumps)
uint inside;  // between pixels of the block
uint edge;    // with the blocks left of and above it in the same cell
KG_STRUCT_END(CellRowJumps)

KG_INLINE uint cell_jump_count(float a, float b, CellBlocksParams p) {
  return cell_depth_jump(a, b, p) ? 1u : 0u;
}

// The jumps of row y of the block with its left neighbours and the row above.
KG_INLINE CellRowJumps cell_row_jumps(KG_BUFFER_PARAM(const float4, points) CellBlockRect r, uint y,
                                      CellBlocksParams p) {
  CellRowJumps jumps;
  jumps.inside = 0u;
  jumps.edge = 0u;
  const uint row = y * p.width;
  for (uint x = r.x0 + 1u; x < r.x1; ++x) {
    jumps.inside += cell_jump_count(points[row + x].z, points[row + x - 1u].z, p);
  }
  if (r.x0 > r.cell_x0 && r.x0 < r.x1) {  // an empty block (past the image's edge) has no edge
    jumps.edge += cell_jump_count(points[row + r.x0].z, points[row + r.x0 - 1u].z, p);
  }
  if (y == r.y0 && y == r.cell_y0) return jumps;
  uint vertical = 0u;
  for (uint x = r.x0; x < r.x1; ++x) {
    vertical += cell_jump_count(points[row + x].z, points[row - p.width + x].z, p);
  }
  if (y > r.y0) {
    jumps.inside += vertical;
  } else {
    jumps.edge += vertical;
  }
  return jumps;
}

// The block's first valid point in row order (xyz; w = 0 when there is none).
KG_INLINE float4 cell_block_reference(KG_BUFFER_PARAM(const float4, points) CellBlockRect r,
                                      CellBlocksParams p) {
  for (uint y = r.y0; y < r.y1; ++y) {
    for (uint x = r.x0; x < r.x1; ++x) {
      const float4 q = points[y * p.width + x];
      if (!kg_isnan(q.x)) return KG_FLOAT4(q.x, q.y, q.z, 1.0f);
    }
  }
  return KG_FLOAT4(0.0f, 0.0f, 0.0f, 0.0f);
}

// Everything the block gives (see the file's comment), written to its entries of sums, counts and
// masks.
KG_INLINE void cell_block_measure(KG_BUFFER_PARAM(const float4, points)
                                      KG_BUFFER_PARAM(const uint, colours)
                                          KG_BUFFER_PARAM(float, sums) KG_BUFFER_PARAM(uint, counts)
                                              KG_BUFFER_PARAM(uint, masks) uint block,
                                  CellBlocksParams p) {
  const CellBlockRect r = cell_block_rect(block, p);
  const float4 reference = cell_block_reference(KG_BUFFER_ARG(points) r, p);
  float s[9];  // sum d, then sum d d^T's upper triangle
  for (uint k = 0u; k < 9u; ++k) s[k] = 0.0f;
  uint count = 0u, red = 0u, green = 0u, blue = 0u, inside = 0u, edge = 0u;
  const uint mask_base = block * p.mask_words;
  for (uint w = 0u; w < p.mask_words; ++w) masks[mask_base + w] = 0u;
  for (uint y = r.y0; y < r.y1; ++y) {
    for (uint x = r.x0; x < r.x1; ++x) {
      const uint i = y * p.width + x;
      const float4 q = points[i];
      if (kg_isnan(q.x)) continue;
      const uint bit = (y - r.y0) * p.block_size + (x - r.x0);
      masks[mask_base + bit / 32u] |= 1u << (bit % 32u);
      const float dx = q.x - reference.x;
      const float dy = q.y - reference.y;
      const float dz = q.z - reference.z;
      s[0] += dx, s[1] += dy, s[2] += dz;
      s[3] += dx * dx, s[4] += dx * dy, s[5] += dx * dz;
      s[6] += dy * dy, s[7] += dy * dz, s[8] += dz * dz;
      ++count;
      red += cell_colour_byte(KG_BUFFER_ARG(colours) 3u * i);
      green += cell_colour_byte(KG_BUFFER_ARG(colours) 3u * i + 1u);
      blue += cell_colour_byte(KG_BUFFER_ARG(colours) 3u * i + 2u);
    }
    const CellRowJumps jumps = cell_row_jumps(KG_BUFFER_ARG(points) r, y, p);
    inside += jumps.inside;
    edge += jumps.edge;
  }
  const uint sums_base = block * KG_CELL_BLOCK_SUMS;
  sums[sums_base] = reference.x;
  sums[sums_base + 1u] = reference.y;
  sums[sums_base + 2u] = reference.z;
  for (uint k = 0u; k < 9u; ++k) sums[sums_base + 3u + k] = s[k];
  const uint counts_base = block * KG_CELL_BLOCK_COUNTS;
  counts[counts_base + KG_CELL_BLOCK_COUNT] = count;
  counts[counts_base + 1u] = red;
  counts[counts_base + 2u] = green;
  counts[counts_base + 3u] = blue;
  counts[counts_base + KG_CELL_BLOCK_INSIDE_JUMPS] = inside;
  counts[counts_base + KG_CELL_BLOCK_EDGE_JUMPS] = edge;
}

KG_RULES_END

#endif
