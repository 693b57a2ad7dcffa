// The ESDF of a 2-D occupancy grid (rules in include/kartograf/mapping/tsdf_slice.hpp,
// occupancy_esdf) on the device: the exact Euclidean distance transform of Felzenszwalb and
// Huttenlocher (2012), twice: once to the occupied cells (written in the free and unknown ones),
// once to the cells that are not occupied (written, negated, in the occupied ones). Each is
//   seed      every cell: squared distance 0 where it is a zero of this transform, else none (-1)
//   envelope  every column, then every row (one work item per line): the lower envelope of the
//             parabolas (q - p)^2 + f[p] over the cells p of the line with f[p] >= 0, evaluated
//             at every cell q; the result is the next line pass's f. Integers throughout, so that
//             every backend gives the same squared distances.
//   write     every cell the transform is for: resolution x sqrt(squared distance) (+infinity
//             where the grid has no zero), negated for the occupied cells.
// Cells hold the band kernel's marks (kernels/tsdf/tsdf_band.h), row-major. The envelope pass
// also serves the 3-D field (kernels/esdf/esdf3.h), one axis at a time.
#ifndef KARTOGRAF_KERNELS_ESDF_H
#define KARTOGRAF_KERNELS_ESDF_H
#include "shaders/prelude.h"

#define KG_ESDF_LOCAL_X 64
#define KG_ESDF_OCCUPIED 2u        // KG_TSDF_BAND_OCCUPIED
#define KG_ESDF_NONE KG_INT64(-1)  // no zero on the line (yet)

KG_RULES_BEGIN

KG_PARAMS_BEGIN(EsdfParams)
KG_PARAM(uint, count)       // seed, write: cells; envelope: lines
KG_PARAM(uint, line_cells)  // envelope: cells per line
// envelope: line i's first cell is (i / lines_per_plane) x plane_stride + (i % lines_per_plane) x
// line_stride (a 2-D grid: one plane of every line; a 3-D box: the y lines, a plane per z)
KG_PARAM(uint, line_stride)
KG_PARAM(uint, lines_per_plane)
KG_PARAM(uint, plane_stride)
KG_PARAM(uint, cell_stride)  // envelope: index step from a cell to the next on its line
KG_PARAM(uint, to_occupied)  // 1: distances to occupied cells; 0: to the other cells
KG_PARAM(float, resolution)  // metres per cell
KG_PARAMS_END(EsdfParams)

// Whether a cell with this mark is a zero of the transform.
KG_INLINE bool esdf_is_zero(uint mark, EsdfParams p) {
  return (mark == KG_ESDF_OCCUPIED) == (p.to_occupied != 0u);
}

// Where the parabola of q (> p) starts to lie below that of p: num / den, den > 0.
KG_INLINE int64_t esdf_meet_num(int64_t fp, int64_t p, int64_t fq, int64_t q) {
  return (fq + q * q) - (fp + p * p);
}

// ---- envelope: the shader declares line_in, line_out, apex, start_num and start_den (one
// element per cell, as the grid).
#if !defined(VULKAN) || defined(KG_ESDF_ENVELOPE_PASS)
KG_FORCE_INLINE void esdf_envelope_line(KG_BUFFER_PARAM(const int64_t, line_in)
                                            KG_BUFFER_PARAM(int64_t, line_out) KG_BUFFER_PARAM(uint,
                                                                                               apex)
                                                KG_BUFFER_PARAM(int64_t, start_num)
                                                    KG_BUFFER_PARAM(int64_t, start_den) uint line,
                                        EsdfParams p) {
  const uint first =
      (line / p.lines_per_plane) * p.plane_stride + (line % p.lines_per_plane) * p.line_stride;
  uint count = 0u;
  for (uint q = 0u; q < p.line_cells; ++q) {
    const int64_t fq = line_in[first + q * p.cell_stride];
    if (fq < KG_INT64(0)) continue;
    // The newest parabola hides those whose part of the envelope starts after it takes over.
    int64_t num = KG_INT64(0), den = KG_INT64(1);
    while (count > 0u) {
      const uint top = apex[first + (count - 1u) * p.cell_stride];
      const int64_t ft = line_in[first + top * p.cell_stride];
      num = esdf_meet_num(ft, KG_INT64(top), fq, KG_INT64(q));
      den = KG_INT64(2) * (KG_INT64(q) - KG_INT64(top));
      if (count == 1u) break;
      const uint at = first + (count - 1u) * p.cell_stride;
      if (num * start_den[at] > start_num[at] * den) break;
      --count;
    }
    const uint slot = first + count * p.cell_stride;
    apex[slot] = q;
    start_num[slot] = num;
    start_den[slot] = den;
    ++count;
  }
  uint j = 0u;
  for (uint q = 0u; q < p.line_cells; ++q) {
    const uint at = first + q * p.cell_stride;
    if (count == 0u) {
      line_out[at] = KG_ESDF_NONE;
      continue;
    }
    while (j + 1u < count && start_num[first + (j + 1u) * p.cell_stride] <=
                                 KG_INT64(q) * start_den[first + (j + 1u) * p.cell_stride])
      ++j;
    const uint a = apex[first + j * p.cell_stride];
    const int64_t d = KG_INT64(q) - KG_INT64(a);
    line_out[at] = d * d + line_in[first + a * p.cell_stride];
  }
}
#endif

// ---- seed: one cell's squared distance before the line passes.
KG_INLINE int64_t esdf_seed_value(uint mark, EsdfParams p) {
  return esdf_is_zero(mark, p) ? KG_INT64(0) : KG_ESDF_NONE;
}

// ---- write: one cell's ESDF value, where this transform is the cell's (else unchanged).
KG_INLINE float esdf_value(int64_t squared, float old_value, uint mark, EsdfParams p) {
  if (esdf_is_zero(mark, p)) return old_value;
  const float distance = squared < KG_INT64(0) ? KG_INFINITY : sqrt(KG_FLOAT(squared));
  return p.to_occupied != 0u ? p.resolution * distance : -p.resolution * distance;
}

KG_RULES_END

#endif
