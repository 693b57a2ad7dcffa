#pragma once
// What every ICP alignment reports, so callers (odometry, loop closure, the pose graph) can judge
// the solution instead of trusting it.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/se3.hpp"
#include "kartograf/registration/rigid_solvers.hpp"

namespace kartograf::registration {

struct IcpResult {
  // Maps source-frame points into the target frame (T_target^-1 T_source for camera-to-world
  // poses).
  Eigen::Isometry3d source_to_target = Eigen::Isometry3d::Identity();
  int iterations = 0;                 // over all levels
  std::vector<int> level_iterations;  // per pyramid level, index 0 = finest
  // The finest level stopped because an update fell below the convergence tolerances (not at its
  // iteration limit, and not for lack of pairs).
  bool converged = false;

  // From the finest level's pairs, with its point selection and gates: those of the last
  // iteration when it converged (taken before an update below the tolerances), else taken anew
  // at the returned transform.
  std::uint64_t considered_count = 0;  // valid selected source points
  std::uint64_t inlier_count = 0;      // of those, pairs that passed every gate
  double fitness = 0;                  // inlier_count / considered_count (overlap estimate)
  // sqrt(mean r^2) over the inliers, r the metric's residual: the plane distance (point-to-plane)
  // or the distance |T p - q| (point-to-point); not robust-weighted. Metres.
  double inlier_rmse = 0;

  // J^T W J (robust weights included, unit measurement noise: divide by sigma^2 for a covariance
  // model) of the point-to-plane residuals of those pairs, whatever the metric (point-to-point
  // residuals when the target has no normals), for the RIGHT perturbation T exp(xi) of the
  // returned transform T, xi = (omega, v): with
  // source = frame j and target = frame i it is the information of the pose-graph edge
  // from i to j (measurement T_i^-1 T_j, mapping/pose_graph.hpp).
  se3::Matrix6d information = se3::Matrix6d::Zero();
  DegeneracyReport degeneracy;  // of the same J^T W J; degeneracy.degenerate is the flag
};

}  // namespace kartograf::registration
