// Depth back-projection; see shaders/backproject.comp for the contract.
typedef struct {
  uint width;
  uint height;
  uint min_units;
  uint max_units;
  float metres_per_unit;
} BackprojectParams;

__kernel void backproject(__global const ushort* depth, __global const float* factors,
                          __global float4* points, const BackprojectParams params) {
  const uint x = get_global_id(0);
  const uint y = get_global_id(1);
  if (x >= params.width || y >= params.height) return;
  const uint index = y * params.width + x;
  const uint d = depth[index];
  float4 point = KG_INVALID_POINT;
  if (d != 0 && d >= params.min_units && d <= params.max_units) {
    const float z = (float)d;
    point = (float4)(z * factors[x], z * factors[params.width + y], z * params.metres_per_unit, 1.0f);
  }
  points[index] = point;
}
