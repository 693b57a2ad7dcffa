#pragma once
// Rigid motions as 6-vectors: the exponential and logarithm of SE(3) and its adjoint. Tangent
// vectors are ordered xi = (omega, v) — rotation first — as in the ICP normal equations
// (registration/icp_sums.hpp), so information matrices from ICP plug into the pose graph.
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kartograf::se3 {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

inline Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// exp(xi) = [R(omega), V(omega) v; 0, 1].
inline Eigen::Isometry3d exp(const Vector6d& xi) {
  const Eigen::Vector3d omega = xi.head<3>();
  const Eigen::Vector3d v = xi.tail<3>();
  const double theta = omega.norm();
  const Eigen::Matrix3d w = hat(omega);
  Eigen::Matrix3d rotation;
  Eigen::Matrix3d left_jacobian;
  if (theta < 1e-8) {
    // Taylor series: the closed forms divide by theta^2 and theta^3.
    rotation = Eigen::Matrix3d::Identity() + w + 0.5 * w * w;
    left_jacobian = Eigen::Matrix3d::Identity() + 0.5 * w + w * w / 6.0;
  } else {
    const double a = std::sin(theta) / theta;
    const double b = (1 - std::cos(theta)) / (theta * theta);
    const double c = (theta - std::sin(theta)) / (theta * theta * theta);
    rotation = Eigen::Matrix3d::Identity() + a * w + b * w * w;
    left_jacobian = Eigen::Matrix3d::Identity() + b * w + c * w * w;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = left_jacobian * v;
  return pose;
}

// The inverse of exp for rotations up to pi (at exactly pi the axis sign is arbitrary).
inline Vector6d log(const Eigen::Isometry3d& pose) {
  const Eigen::AngleAxisd angle_axis(pose.linear());
  const double theta = angle_axis.angle();
  const Eigen::Vector3d omega = angle_axis.axis() * theta;
  const Eigen::Matrix3d w = hat(omega);
  Eigen::Matrix3d inverse_left_jacobian;
  if (theta < 1e-8) {
    inverse_left_jacobian = Eigen::Matrix3d::Identity() - 0.5 * w + w * w / 12.0;
  } else {
    const double half = 0.5 * theta;
    const double k = (1 - half * std::cos(half) / std::sin(half)) / (theta * theta);
    inverse_left_jacobian = Eigen::Matrix3d::Identity() - 0.5 * w + k * w * w;
  }
  Vector6d xi;
  xi.head<3>() = omega;
  xi.tail<3>() = inverse_left_jacobian * pose.translation();
  return xi;
}

// Ad(T) with T exp(xi) T^-1 = exp(Ad(T) xi).
inline Matrix6d adjoint(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d r = pose.linear();
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = r;
  ad.bottomRightCorner<3, 3>() = r;
  ad.bottomLeftCorner<3, 3>() = hat(pose.translation()) * r;
  return ad;
}

// Rotation angle (radians) and translation length of a motion: how far it is from identity.
inline double rotation_angle(const Eigen::Isometry3d& pose) {
  return Eigen::AngleAxisd(pose.linear()).angle();
}

}  // namespace kartograf::se3
