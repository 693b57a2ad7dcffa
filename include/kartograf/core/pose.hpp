#pragma once
// Poses from the 4x4 matrices data sets store: the nearest rotation of the 3x3 block; and the check
// that a pose given by a caller is a rigid motion.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kartograf {

// The nearest rotation (SVD) of a 3x3 block, and the pose made of it and a translation.
// A reflection (det < 0) is an Error.
Eigen::Isometry3d orthonormalized_pose(const Eigen::Matrix4d& matrix);

// Finite, and its 3x3 block a rotation: R^T R within `tolerance` of the identity (per entry),
// det R > 0.
bool is_rigid(const Eigen::Isometry3d& pose, double tolerance = 1e-3);

}  // namespace kartograf
