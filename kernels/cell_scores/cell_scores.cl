// OpenCL wrapper of kernels/cell_scores/cell_scores.h: one job per work-item.
#include "kernels/cell_scores/cell_scores.h"

__kernel void cell_scores(__global const float4* points, __global const uint* jobs,
                          __global const uint* candidates, __global const float4* planes,
                          __global uint* choices, __global float* distances,
                          const CellScoresParams params) {
  const uint job = get_global_id(0);
  if (job >= params.job_count) return;
  cell_score_job(points, jobs, candidates, planes, choices, distances, job, params);
}
