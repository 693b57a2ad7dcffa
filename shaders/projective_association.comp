#version 450
// Projective data association; rules in include/kartograf/registration/projective_association.hpp.
// Writes one entry per source point: the target pixel index, -1 (no match) or -2 (not selected).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Source { vec4 source[]; };
layout(std430, binding = 1) readonly buffer SourceNormals { vec4 source_normals[]; };  // optional
layout(std430, binding = 2) readonly buffer Target { vec4 target[]; };
layout(std430, binding = 3) readonly buffer TargetNormals { vec4 target_normals[]; };  // optional
// R (row-major 3x3), t, fx, fy, cx, cy, max squared distance, min normal cosine.
layout(std430, binding = 4) readonly buffer Frame { float frame[]; };
layout(std430, binding = 5) writeonly buffer Correspondences { int correspondences[]; };

layout(push_constant) uniform Params {
  uint source_count;
  uint source_width;  // 0: unorganized source
  uint target_width;
  uint target_height;
  uint subsample;
  uint use_normals;
  uint search_radius;
} params;

// Float arithmetic (single precision is what GPUs are fast at): the pixel is off by ~1e-4 of a
// pixel and the gates by ~1 um at 5 m. Each product and sum is spelled out in one fixed order and
// `precise` forbids fused multiply-adds, so every backend rounds the same way.
vec3 rotate(vec3 p) {
  return vec3(frame[0] * p.x + frame[1] * p.y + frame[2] * p.z,
              frame[3] * p.x + frame[4] * p.y + frame[5] * p.z,
              frame[6] * p.x + frame[7] * p.y + frame[8] * p.z);
}

int associate(uint i) {
  const uint row = params.source_width == 0u ? 0u : i / params.source_width;
  if ((i + row) % params.subsample != 0u) return -2;
  const vec4 p = source[i];
  if (!is_valid_point(p)) return -1;
  precise const vec3 moved = rotate(p.xyz) + vec3(frame[9], frame[10], frame[11]);
  if (!(moved.z > 0.0)) return -1;
  precise const float u = floor(frame[12] * moved.x / moved.z + frame[14] + 0.5);
  precise const float v = floor(frame[13] * moved.y / moved.z + frame[15] + 0.5);
  const int r = int(params.search_radius);
  // Pixels outside the image are skipped below; bound first so the conversion cannot overflow.
  if (!(u >= float(-r) && v >= float(-r) && u < float(params.target_width + r) &&
        v < float(params.target_height + r))) {
    return -1;
  }
  precise vec3 rotated_normal = vec3(0.0);
  if (params.use_normals != 0u) {
    const vec4 np = source_normals[i];
    if (!is_valid_point(np)) return -1;
    rotated_normal = rotate(np.xyz);
  }
  int best = -1;
  float best_distance_sq = frame[16];  // max distance^2: farther candidates never win
  for (int dv = -r; dv <= r; ++dv) {
    for (int du = -r; du <= r; ++du) {
      const int x = int(u) + du;
      const int y = int(v) + dv;
      if (x < 0 || y < 0 || x >= int(params.target_width) || y >= int(params.target_height)) continue;
      const uint j = uint(y) * params.target_width + uint(x);
      const vec4 q = target[j];
      if (!is_valid_point(q)) continue;
      precise const vec3 d = moved - q.xyz;
      precise const float distance_sq = d.x * d.x + d.y * d.y + d.z * d.z;
      if (!(distance_sq <= best_distance_sq) || (best >= 0 && distance_sq == best_distance_sq)) continue;
      if (params.use_normals != 0u) {
        const vec4 nq = target_normals[j];
        precise const float cosine = rotated_normal.x * nq.x + rotated_normal.y * nq.y + rotated_normal.z * nq.z;
        if (!is_valid_point(nq) || !(cosine >= frame[17])) continue;
      }
      best = int(j);
      best_distance_sq = distance_sq;
    }
  }
  return best;
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.source_count) return;
  correspondences[i] = associate(i);
}
