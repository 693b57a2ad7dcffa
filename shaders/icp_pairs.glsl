// Loading one correspondence for the ICP sums. Per-pair arithmetic is in double: residuals near
// convergence are millimetres on coordinates of metres, which float would resolve to ~1e-4.
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
