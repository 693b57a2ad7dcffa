#pragma once
// How uncertain a relative pose chained from odometry steps is: the first-order covariance of
// T_from^-1 T_to when each step's motion D_k (frame k to k+1) carries an independent error,
// D_k exp(xi_k) with xi_k ~ N(0, Omega_k^-1) (the steps' edge information, right perturbation,
// rotation first as se3.hpp). Moving each error to the end of the chain,
//   Sigma = sum_k Ad(P_k^-1) Omega_k^-1 Ad(P_k^-1)^T,  P_k = T_(k+1)^-1 T_to,
// in the tangent of T_from^-1 T_to's right perturbation. A degenerate step's free directions
// carry the motion model's prior (OdometryParams::fallback_sigma_*), so the chain is as uncertain
// there as the odometry was: a loop's correction along them is plausible, one across them is not.
#include <cstddef>
#include <span>

#include <Eigen/Geometry>

#include "kartograf/core/se3.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::mapping {

// Throws Error when from >= to, a pose is missing, a step from `from` to `to` has no edge
// (from + 1 == to) among `steps`, or a step's information is not positive definite.
se3::Matrix6d chain_covariance(std::span<const registration::RelativePose> steps,
                               std::span<const Eigen::Isometry3d> poses, std::size_t from,
                               std::size_t to);

// The squared Mahalanobis distance of `correction` (a motion, as T_expected^-1 T) under
// `covariance` (its right-perturbation tangent).
double mahalanobis_squared(const Eigen::Isometry3d& correction, const se3::Matrix6d& covariance);

}  // namespace kartograf::mapping
