// One pyramid step: 2x2 blocks of points (and colours) -> one coarse pixel; rules in
// include/kartograf/registration/frame_pyramid.hpp.
typedef struct {
  uint fine_width;
  uint coarse_width;
  uint coarse_height;
  uint has_colors;
  float max_depth_jump;
} PyramidDownsampleParams;

__kernel void pyramid_downsample(__global const float4* fine_points, __global const uint* fine_colors,
                                 __global float4* coarse_points, __global uint* coarse_colors,
                                 const PyramidDownsampleParams params) {
  const uint x = get_global_id(0);
  const uint y = get_global_id(1);
  if (x >= params.coarse_width || y >= params.coarse_height) return;
  const uint corner = 2 * y * params.fine_width + 2 * x;
  const uint block[4] = {corner, corner + 1, corner + params.fine_width, corner + params.fine_width + 1};
  float z_min = 0.0f;
  bool any = false;
  for (int k = 0; k < 4; ++k) {
    const float4 p = fine_points[block[k]];
    if (kg_is_valid_point(p) && (!any || p.z < z_min)) {
      z_min = p.z;
      any = true;
    }
  }
  float4 point = KG_INVALID_POINT;
  uint color = 0;
  if (any) {
    float3 sum = (float3)(0.0f);
    uint3 color_sum = (uint3)(0);
    uint count = 0;
    for (int k = 0; k < 4; ++k) {
      const float4 p = fine_points[block[k]];
      if (!kg_is_valid_point(p) || !(p.z - z_min <= params.max_depth_jump * z_min)) continue;
      sum += p.xyz;
      ++count;
      if (params.has_colors != 0) {
        const uint c = fine_colors[block[k]];
        color_sum += (uint3)(c & 0xff, (c >> 8) & 0xff, (c >> 16) & 0xff);
      }
    }
    // Multiplying by a rounded reciprocal is exact IEEE everywhere; division need not be.
    const float inverse[5] = {0.0f, 1.0f, 0.5f, 0.333333343267f, 0.25f};
    point = (float4)(sum * inverse[count], 1.0f);
    const uint3 mean = (color_sum + (uint3)(count / 2)) / count;
    color = mean.x | (mean.y << 8) | (mean.z << 16);
  }
  const uint index = y * params.coarse_width + x;
  coarse_points[index] = point;
  if (params.has_colors != 0) coarse_colors[index] = color;
}
