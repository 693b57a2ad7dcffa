#pragma once
// Normals of an organized point image from its 4-neighbours (docs/methods.md M2 step 1).
//
// Rules, identical on every backend: a neighbour is usable when it is valid and its depth differs
// from the centre's by at most max_depth_jump * z_centre (evaluated in float). The horizontal
// tangent is right - left when both are usable, else the one-sided difference with the usable one;
// likewise the vertical tangent. No tangent on an axis, an invalid centre or parallel tangents give
// an all-NaN normal. Normals are unit length and face the camera (n . p <= 0); w is 0.
#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::geometry {

struct NormalParams {
  // Depth discontinuity threshold relative to depth (Kinect noise grows with z; 0.05 keeps
  // object edges from bridging to the background at 1-4 m).
  float max_depth_jump = 0.05f;
};

void estimate_normals(const compute::Context& context, const compute::DeviceImage<Point4f>& points,
                      compute::DeviceImage<Point4f>& normals, const NormalParams& params = {});

// Convenience: host images in and out.
NormalImage estimate_normals(const compute::Context& context, const PointImage& points,
                             const NormalParams& params = {});

}  // namespace kartograf::geometry
