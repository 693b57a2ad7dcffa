#include "kartograf/core/pose.hpp"

#include <Eigen/SVD>

#include "kartograf/core/error.hpp"

namespace kartograf {

Eigen::Isometry3d orthonormalized_pose(const Eigen::Matrix4d& matrix) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix.topLeftCorner<3, 3>(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  require(rotation.determinant() > 0, "pose matrix is a reflection, not a rotation");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = matrix.topRightCorner<3, 1>();
  return pose;
}

bool is_rigid(const Eigen::Isometry3d& pose, double tolerance) {
  const Eigen::Matrix3d r = pose.linear();
  return pose.matrix().allFinite() &&
         (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < tolerance &&
         r.determinant() > 0;
}

}  // namespace kartograf
