// The cells mode's pixel scores (src/segmentation/cell_planes.cpp, assign_cell_pixels): per pixel
// of each scoring job (a cell's or block's rectangle with its candidate planes), the candidate
// whose distance allowance the point is deepest within, or none when it is within none; and its
// squared distance to that candidate. The rule is plane_score's (distance / (base facing), with
// distance = |n . p + offset|, facing = max(|n . p| / |p|, min_facing), base = distance_base +
// distance_per_z2 z^2), compared squared by cross-multiplying, without divisions or roots, and
// with no fused multiply-add, so that every backend gives the CPU's choices. One job per
// work-item, its pixels row by row. The host path on the CPU backend scores four pixels at a time
// with the same operations (ScoreRule in cell_planes.cpp).
#ifndef KARTOGRAF_KERNELS_CELL_SCORES_H
#define KARTOGRAF_KERNELS_CELL_SCORES_H
#include "shaders/prelude.h"

#define KG_CELL_SCORES_LOCAL_X 64

// Per job, uints: the rectangle [x0, x1) x [y0, y1), its first candidate in `candidates`, how many,
// and its first pixel's entry in the outputs (its pixels follow row by row).
#define KG_CELL_JOB_WORDS 7u
#define KG_CELL_NO_CHOICE 0xffffffffu

KG_RULES_BEGIN

KG_PARAMS_BEGIN(CellScoresParams)
KG_PARAM(uint, width)
KG_PARAM(uint, job_count)
KG_PARAM(float, distance_base)
KG_PARAM(float, distance_per_z2)
KG_PARAM(float, min_facing)
KG_PARAMS_END(CellScoresParams)

KG_STRUCT_BEGIN(CellChoice)
uint candidate;   // index among the job's candidates, or KG_CELL_NO_CHOICE
float distance2;  // squared distance to it (1 when none)
KG_STRUCT_END(CellChoice)

// The choice for point q among `count` candidate planes from `first` (planes: n, offset).
KG_INLINE CellChoice cell_choice(KG_BUFFER_PARAM(const uint, candidates)
                                     KG_BUFFER_PARAM(const float4, planes) float4 q, uint first,
                                 uint count, CellScoresParams p) {
#if defined(__OPENCL_C_VERSION__)
#pragma OPENCL FP_CONTRACT OFF
#endif
  KG_PRECISE const float range2 = q.x * q.x + q.y * q.y + q.z * q.z;
  KG_PRECISE const float floor2 = (p.min_facing * p.min_facing) * range2;
  float best_d2 = 1.0f;
  float best_s2 = 0.0f;
  uint choice = KG_CELL_NO_CHOICE;
  for (uint k = 0u; k < count; ++k) {
    const float4 n = planes[candidates[first + k]];
    KG_PRECISE const float along = n.x * q.x + n.y * q.y + n.z * q.z;
    KG_PRECISE const float d = along + n.w;
    KG_PRECISE const float d2 = d * d;
    KG_PRECISE const float a2 = along * along;
    const float s2 = a2 > floor2 ? a2 : floor2;
    KG_PRECISE const float left = d2 * best_s2;
    KG_PRECISE const float right = best_d2 * s2;
    if (left < right) {
      best_d2 = d2;
      best_s2 = s2;
      choice = k;
    }
  }
  KG_PRECISE const float base = p.distance_base + p.distance_per_z2 * q.z * q.z;
  KG_PRECISE const float within = best_d2 * range2;
  KG_PRECISE const float allowed = base * base * best_s2;
  CellChoice result;
  result.candidate = within < allowed ? choice : KG_CELL_NO_CHOICE;
  result.distance2 = best_d2;
  return result;
}

// Job `job`'s pixels: their choices and squared distances.
KG_INLINE void cell_score_job(KG_BUFFER_PARAM(const float4, points)
                                  KG_BUFFER_PARAM(const uint, jobs)
                                      KG_BUFFER_PARAM(const uint, candidates)
                                          KG_BUFFER_PARAM(const float4, planes)
                                              KG_BUFFER_PARAM(uint, choices)
                                                  KG_BUFFER_PARAM(float, distances) uint job,
                              CellScoresParams p) {
  const uint base = job * KG_CELL_JOB_WORDS;
  const uint x0 = jobs[base], y0 = jobs[base + 1u], x1 = jobs[base + 2u], y1 = jobs[base + 3u];
  const uint first = jobs[base + 4u], count = jobs[base + 5u];
  uint slot = jobs[base + 6u];
  for (uint y = y0; y < y1; ++y) {
    for (uint x = x0; x < x1; ++x) {
      const CellChoice c = cell_choice(KG_BUFFER_ARG(candidates) KG_BUFFER_ARG(planes)
                                           points[y * p.width + x],
                                       first, count, p);
      choices[slot] = c.candidate;
      distances[slot] = c.distance2;
      ++slot;
    }
  }
}

KG_RULES_END

#endif
