#pragma once
// Exact ray casting against the axis-aligned world. Floor and ceiling are the planes z = 0 and
// z = height (analytic); every other surface is a face of a box, found through a uniform 2-D grid
// over the floor plan (each cell lists the boxes whose footprint overlaps it), traversed along
// the ray by a DDA walk: only the boxes near the ray are tested, and the walk stops at the first
// cell that contains a hit. Thread-safe: cast() is const and allocates nothing.
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "kartograf/synth/world.hpp"

namespace kartograf::synth {

struct SurfaceHit {
  double t = 0;  // ray parameter: point = origin + t * direction
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Face face = Face::pos_z;  // the surface's outward normal (towards the ray origin)
  Label plane = 0;          // 0 only where the ray slips through a seam onto a hidden face
  int material = 0;
};

// The albedo of the surface at a hit: its material's texture at the two world coordinates that
// span the face.
Eigen::Vector3d surface_albedo(const World& world, const SurfaceHit& hit);

class RayCaster {
 public:
  // Keeps a reference to world: it must outlive the caster.
  explicit RayCaster(const World& world, double cell_size = 0.5);

  // The first surface along origin + t * direction for t > 0 (direction need not be unit
  // length); nullopt when the ray escapes (only possible from outside the building).
  std::optional<SurfaceHit> cast(const Eigen::Vector3d& origin,
                                 const Eigen::Vector3d& direction) const;

  const World& world() const { return world_; }

 private:
  // A box and its index in world.solids.
  struct Part {
    double bounds[2][3];  // min, max
    int solid;
  };
  // The boxes of one piece of furniture (or a single wall box) behind one bounding box: a ray
  // that misses the bounding box skips them all.
  struct Group {
    double bounds[2][3];         // min, max over the parts
    std::uint32_t first, count;  // parts_[first .. first + count)
  };
  void resolve(SurfaceHit& hit, int solid) const;

  const World& world_;
  double cell_ = 0.5;
  Eigen::Vector2d grid_min_ = Eigen::Vector2d::Zero();
  int nx_ = 0, ny_ = 0;
  std::vector<Part> parts_;
  std::vector<std::uint32_t> cell_start_;  // CSR: cell c lists groups_[cell_start_[c] .. [c+1])
  std::vector<Group> groups_;
};

}  // namespace kartograf::synth
