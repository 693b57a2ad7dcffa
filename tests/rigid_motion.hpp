#pragma once
// A fixed rigid motion for the trajectory metric tests (core only: Eigen).
#include <Eigen/Geometry>

namespace kartograf::testing {

// A rotation of 0.5 rad about (1, 2, 3) and a translation of (1, -2, 0.5) m.
inline Eigen::Isometry3d some_rigid_motion() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  return t;
}

}  // namespace kartograf::testing
