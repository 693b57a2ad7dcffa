#version 450
// Vulkan wrapper of kernels/cell_scores/cell_scores.h: one job per invocation.
#extension GL_GOOGLE_include_directive : require
#include "shaders/prelude.h"

layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) readonly buffer Jobs { uint jobs[]; };
layout(std430, binding = 2) readonly buffer Candidates { uint candidates[]; };
layout(std430, binding = 3) readonly buffer Planes { vec4 planes[]; };
layout(std430, binding = 4) writeonly buffer Choices { uint choices[]; };
layout(std430, binding = 5) writeonly buffer Distances { float distances[]; };

#include "kernels/cell_scores/cell_scores.h"

layout(local_size_x = KG_CELL_SCORES_LOCAL_X) in;
KG_PUSH_PARAMS(CellScoresParams);

void main() {
  const uint job = gl_GlobalInvocationID.x;
  if (job >= params.job_count) return;
  cell_score_job(job, params);
}
