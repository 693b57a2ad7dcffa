#pragma once
// The rules of kernels/voxel_hash_nearest/voxel_hash_nearest.h (moved points, squared distances,
// the tie-break) for the k-d tree finder, which searches on the host, and the per-source-point
// driver of its search.
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/registration/correspondence_finder.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kernels/correspondence/selection.h"
#include "kernels/voxel_hash_nearest/voxel_hash_nearest.h"
#include "registration/association_checks.hpp"

namespace kartograf::registration::detail {

inline kernels::float4 to_float4(const Point4f& p) {
  return {p.x(), p.y(), p.z(), p.w()};
}

// What one find() needs besides the clouds; the frame as KG_NEAREST_FRAME_* lays it out (the cell
// inverse is the grid's only).
struct NearestQuery {
  std::array<double, KG_NEAREST_FRAME_VALUES> frame{};
  bool use_normals = false;

  double max_distance_sq() const { return frame[KG_NEAREST_FRAME_MAX_DISTANCE_SQ]; }
  double min_normal_cosine() const { return frame[KG_NEAREST_FRAME_MIN_COSINE]; }

  Eigen::Vector3d rotate(double x, double y, double z) const {
    const kernels::double3 r = kernels::nearest_rotate(frame.data(), {x, y, z});
    return {r.x, r.y, r.z};
  }
  Eigen::Vector3d move(const Point4f& p) const {
    const kernels::double3 moved = kernels::nearest_move(frame.data(), to_float4(p));
    return {moved.x, moved.y, moved.z};
  }
};

inline NearestQuery make_query(const Eigen::Isometry3d& pose, const AssociationParams& params) {
  NearestQuery query;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) query.frame[KG_NEAREST_FRAME_R + 3 * r + c] = pose.linear()(r, c);
    query.frame[KG_NEAREST_FRAME_T + r] = pose.translation()(r);
  }
  query.frame[KG_NEAREST_FRAME_MAX_DISTANCE_SQ] = params.max_distance * params.max_distance;
  query.frame[KG_NEAREST_FRAME_MIN_COSINE] =
      std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
  query.use_normals = params.max_normal_angle_deg < 180.0;
  return query;
}

// The best candidate so far: the smallest squared distance <= the bound, the lowest index among
// equals. Starts at the bound with no index, so a candidate exactly at max_distance counts.
struct Nearest {
  explicit Nearest(double max_distance_sq) : distance_sq(max_distance_sq) {}
  bool improves(std::int32_t j, double d) const {
    return kernels::nearest_improves(d, j, {index, distance_sq});
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
    if (!kernels::correspondence_selected(index, width, k)) {
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
