#pragma once
// Poses from the 4x4 matrices data sets store: the nearest rotation of the 3x3 block.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kartograf {

// The nearest rotation (SVD) of a 3x3 block, and the pose made of it and a translation.
// A reflection (det < 0) is an Error.
Eigen::Isometry3d orthonormalized_pose(const Eigen::Matrix4d& matrix);

}  // namespace kartograf
