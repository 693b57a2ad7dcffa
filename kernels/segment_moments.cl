// Per-label moments as 64-bit fixed-point atomic sums; see shaders/segment_moments.comp.
typedef struct {
  uint point_count;
  uint label_count;
  float origin_x;
  float origin_y;
  float origin_z;
  float max_offset;
  float first_scale;
  float second_scale;
} SegmentMomentParams;

__kernel void segment_moments(__global const float4* points, __global const uint* labels,
                              __global long* moments, __global uint* status,
                              const SegmentMomentParams params) {
  const uint i = get_global_id(0);
  if (i >= params.point_count) return;
  const uint label = labels[i];
  const float4 p = points[i];
  if (label == 0xffffffffu || !kg_is_valid_point(p)) return;
  if (label >= params.label_count) {
    atomic_inc(&status[1]);
    return;
  }
  const double dx = (double)p.x - (double)params.origin_x;
  const double dy = (double)p.y - (double)params.origin_y;
  const double dz = (double)p.z - (double)params.origin_z;
  const double bound = (double)params.max_offset;
  if (fabs(dx) > bound || fabs(dy) > bound || fabs(dz) > bound) {
    atomic_inc(&status[0]);
    return;
  }
  const uint base = label * 10u;
  const double s1 = (double)params.first_scale;
  const double s2 = (double)params.second_scale;
  atom_add(&moments[base], 1L);
  kg_add_fixed(moments, base + 1, dx, s1);
  kg_add_fixed(moments, base + 2, dy, s1);
  kg_add_fixed(moments, base + 3, dz, s1);
  kg_add_fixed(moments, base + 4, dx * dx, s2);
  kg_add_fixed(moments, base + 5, dx * dy, s2);
  kg_add_fixed(moments, base + 6, dx * dz, s2);
  kg_add_fixed(moments, base + 7, dy * dy, s2);
  kg_add_fixed(moments, base + 8, dy * dz, s2);
  kg_add_fixed(moments, base + 9, dz * dz, s2);
}
