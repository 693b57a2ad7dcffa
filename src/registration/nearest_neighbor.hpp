#pragma once
// The rules both nearest-neighbour finders (k-d tree, voxel-hash grid) share, in the arithmetic
// of the voxel_hash_nearest kernels: moved points, squared distances in a fixed order (no
// contraction, so every backend computes the same doubles), the normal gate, the tie-break, and
// the per-source-point driver of the CPU paths.
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/registration/correspondence_finder.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "registration/association_checks.hpp"

namespace kartograf::registration::detail {

// What one find() needs besides the clouds; frame layout of shaders/voxel_hash_nearest.comp:
// R (row-major), t, cell inverse (grid only), max distance^2, min normal cosine.
struct NearestQuery {
  std::array<double, 15> frame{};
  bool use_normals = false;

  double max_distance_sq() const { return frame[13]; }
  double min_normal_cosine() const { return frame[14]; }

  Eigen::Vector3d rotate(double x, double y, double z) const {
    return {frame[0] * x + frame[1] * y + frame[2] * z, frame[3] * x + frame[4] * y + frame[5] * z,
            frame[6] * x + frame[7] * y + frame[8] * z};
  }
  Eigen::Vector3d move(const Point4f& p) const {
    const Eigen::Vector3d r = rotate(p.x(), p.y(), p.z());
    return {r.x() + frame[9], r.y() + frame[10], r.z() + frame[11]};
  }
};

inline NearestQuery make_query(const Eigen::Isometry3d& pose, const AssociationParams& params) {
  NearestQuery query;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) query.frame[3 * r + c] = pose.linear()(r, c);
    query.frame[9 + r] = pose.translation()(r);
  }
  query.frame[13] = params.max_distance * params.max_distance;
  query.frame[14] = std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
  query.use_normals = params.max_normal_angle_deg < 180.0;
  return query;
}

inline double squared_distance(const Eigen::Vector3d& a, const Point4f& b) {
  const double dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

// The best candidate so far: the smallest squared distance <= the bound, the lowest index among
// equals. Starts at the bound with no index, so a candidate exactly at max_distance counts.
struct Nearest {
  explicit Nearest(double max_distance_sq) : distance_sq(max_distance_sq) {}
  bool improves(std::int32_t j, double d) const {
    return d < distance_sq || (d == distance_sq && (index < 0 || j < index));
  }
  void take(std::int32_t j, double d) {
    index = j;
    distance_sq = d;
  }
  std::int32_t index = kNoMatch;
  double distance_sq;
};

// The common rules, and a search radius (max_distance) that a grid or tree can bound.
inline void validate(const CloudView& source, const CloudView& target,
                     const AssociationParams& params, bool use_normals, const std::string& what) {
  check_association_inputs(source, target, params, use_normals, what);
  require(std::isfinite(params.max_distance) && params.max_distance > 0,
          what + ": max_distance must be finite and > 0");
}

// Fills out[i] for every source point: kNotSelected, kNoMatch, or search(moved, gate) with the
// source normal rotated into the target frame when the gate is on.
template <class Search>
void find_each(const NearestQuery& query, std::span<const Point4f> source,
               std::span<const Point4f> source_normals, std::span<const Point4f> target_normals,
               std::uint32_t width, std::uint32_t k, std::span<std::int32_t> out, Search&& search) {
  for (std::size_t i = 0; i < source.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(i);
    if (!is_selected(index, width, k)) {
      out[i] = kNotSelected;
      continue;
    }
    out[i] = kNoMatch;
    if (!is_valid(source[i])) continue;
    NormalGate gate;
    if (query.use_normals) {
      const Point4f& n = source_normals[i];
      if (!is_valid(n)) continue;
      gate = {target_normals, query.rotate(n.x(), n.y(), n.z()), query.min_normal_cosine()};
    }
    out[i] = search(query.move(source[i]), query.use_normals ? &gate : nullptr);
  }
}

}  // namespace kartograf::registration::detail
