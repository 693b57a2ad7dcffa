#version 450
// Voxel downsampling, pass 6 of 6: one output point per voxel from its sums (layout in
// voxel_downsample_accumulate.comp): centroid = (voxel + mean fraction) / inverse_size; normal =
// the normalised sum of the valid normals (NaN when there is none or |sum| < 1e-3 x their count);
// colour = per-channel mean rounded half up.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "voxel_hash.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer VoxelKeys { uint64_t voxel_keys[]; };
layout(std430, binding = 1) readonly buffer Sums { int64_t sums[]; };
layout(std430, binding = 2) writeonly buffer OutPoints { vec4 out_points[]; };
layout(std430, binding = 3) writeonly buffer OutNormals { vec4 out_normals[]; };  // optional
layout(std430, binding = 4) writeonly buffer OutColors { uint out_colors[]; };    // optional

layout(push_constant) uniform Params {
  uint voxel_count;
  uint stride;
  uint has_normals;
  uint has_colors;
  float inverse_size;
  float position_scale;
  float normal_scale;
} params;

void main() {
  const uint v = gl_GlobalInvocationID.x;
  if (v >= params.voxel_count) return;
  const uint base = v * params.stride;
  const int64_t count = sums[base];
  const dvec3 fraction = dvec3(sums[base + 1u], sums[base + 2u], sums[base + 3u]) /
                         (double(count) * double(params.position_scale));
  const dvec3 mean_point = (voxel_of_key(voxel_keys[v]) + fraction) / double(params.inverse_size);
  out_points[v] = vec4(vec3(mean_point), 1.0);
  if (params.has_normals != 0u) {
    const int64_t normal_count = sums[base + 7u];
    const dvec3 sum = dvec3(sums[base + 4u], sums[base + 5u], sums[base + 6u]) /
                      double(params.normal_scale);
    const double norm = sqrt(dot(sum, sum));
    out_normals[v] = normal_count == 0l || norm < 1e-3 * double(normal_count)
                         ? kInvalidPoint
                         : vec4(vec3(sum / norm), 0.0);
  }
  if (params.has_colors != 0u) {
    const uint color_base = base + (params.has_normals != 0u ? 8u : 4u);
    const uint64_t n = uint64_t(count);
    uint packed = 0u;
    for (uint channel = 0u; channel < 3u; ++channel) {
      const uint64_t mean = (2ul * uint64_t(sums[color_base + channel]) + n) / (2ul * n);
      packed |= uint(mean) << (8u * channel);
    }
    out_colors[v] = packed;
  }
}
