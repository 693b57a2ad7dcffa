#pragma once
// The input rules every correspondence finder checks (projective association, k-d tree, voxel
// hash): both point buffers, a source camera that fits its points, indices that fit an int32,
// the point selection, the normal gate's angle and the normals it needs. Each finder adds its own
// rules (the target camera, the search radius, the distance bound) after these.
#include <cmath>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/registration/correspondence_finder.hpp"

namespace kartograf::registration::detail {

// Throws Error "<what>: <problem>" for the first rule that source, target or params break.
inline void check_association_inputs(const CloudView& source, const CloudView& target,
                                     const AssociationParams& params, bool use_normals,
                                     const std::string& what) {
  require(source.points && target.points, what + ": source and target points are required");
  require(!source.camera || source.size() == static_cast<std::size_t>(source.camera->width) *
                                                 static_cast<std::size_t>(source.camera->height),
          what + ": source points do not match the source camera's image size");
  require(source.size() < (std::size_t{1} << 31) && target.size() < (std::size_t{1} << 31),
          what + ": more than 2^31 points");
  require(params.subsample >= 1,
          what + ": subsample must be >= 1, got " + std::to_string(params.subsample));
  require(!std::isnan(params.max_normal_angle_deg) && params.max_normal_angle_deg >= 0,
          what + ": max_normal_angle_deg must be >= 0");
  if (use_normals) {
    require(
        source.normals && target.normals,
        what +
            ": the normal gate needs source and target normals (or max_normal_angle_deg >= 180)");
    require(source.normals->size() == source.size() && target.normals->size() == target.size(),
            what + ": normals and points differ in count");
  }
}

}  // namespace kartograf::registration::detail
