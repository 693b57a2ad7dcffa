// Loading one correspondence for the ICP sums. Per-pair arithmetic is in double: residuals near
// convergence are millimetres on coordinates of metres, which float would resolve to ~1e-4.
// Rules in include/kartograf/registration/icp_sums.hpp, robust kernels in robust_kernel.hpp.
struct Pair {
  dvec3 moved;   // R p + t
  dvec3 target;  // q
  double distance_sq;
  double weight;
  uint target_index;
};

bool load_pair(uint i, out Pair pair) {
  pair.moved = dvec3(0.0);
  pair.target = dvec3(0.0);
  pair.distance_sq = 0.0;
  pair.weight = 1.0;
  pair.target_index = i;
  const vec4 p = source[i];
  if (!is_valid_point(p)) return false;
  if (params.has_correspondences != 0u) {
    const int j = correspondences[i];
    if (j < 0 || uint(j) >= params.target_count) return false;
    pair.target_index = uint(j);
  } else if (i >= params.target_count) {
    return false;
  }
  if (params.has_weights != 0u) {
    pair.weight = double(weights[i]);
    if (!(pair.weight > 0.0)) return false;
  }
  const vec4 q = target[pair.target_index];
  if (!is_valid_point(q)) return false;
  const dvec3 ps = dvec3(p.xyz);
  pair.moved = dvec3(frame[0] * ps.x + frame[1] * ps.y + frame[2] * ps.z + frame[9],
                     frame[3] * ps.x + frame[4] * ps.y + frame[5] * ps.z + frame[10],
                     frame[6] * ps.x + frame[7] * ps.y + frame[8] * ps.z + frame[11]);
  pair.target = dvec3(q.xyz);
  const dvec3 d = pair.moved - pair.target;
  pair.distance_sq = dot(d, d);
  return pair.distance_sq <= frame[18];
}

// A valid source point whose entry is not kNotSelected (-2 or lower): the fitness denominator.
bool is_considered(uint i) {
  if (!is_valid_point(source[i])) return false;
  return params.has_correspondences == 0u || correspondences[i] >= -1;
}

// The robust kernel's weight of a residual; frame[19] is its scale c.
double robust_weight(double residual) {
  const double r = abs(residual);
  const double c = frame[19];
  if (params.robust_kernel == 1u) return r <= c ? 1.0 : c / r;  // Huber
  if (params.robust_kernel == 2u) {                              // Tukey
    if (!(r < c)) return 0.0;
    const double u = r / c;
    const double s = 1.0 - u * u;
    return s * s;
  }
  return 1.0;
}
