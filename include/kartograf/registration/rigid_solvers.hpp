#pragma once
// The error metrics' solvers of the ICP engine: from one iteration's sums (icp_sums.hpp) to a
// motion update Delta, applied as T <- Delta T (Delta acts in the target frame), and the analysis
// of the normal equations (information matrix, degeneracy) that every ICP result reports.
#include <optional>

#include <Eigen/Geometry>

#include "kartograf/core/se3.hpp"
#include "kartograf/registration/icp_sums.hpp"

namespace kartograf::registration {

// Point-to-point, closed form (Arun, Huang & Blostein 1987): with the cross-covariance
// H = U S V^T, R = V D U^T where D = diag(1, 1, det(V U^T)) guards against a reflection, and
// t = target_mean - R source_mean. Empty with fewer than 3 pairs or no weight.
std::optional<Eigen::Isometry3d> solve_point_to_point(const PointToPointSums& sums);

// Point-to-plane, one Gauss-Newton step: x = -(J^T J)^-1 J^T r by LDLT (damped by 1e-9 x the mean
// diagonal, so an exactly singular system, e.g. a single plane, stays finite), applied about the
// pivot as Delta = T(pivot) exp(x) T(-pivot). Empty with fewer than 6 pairs or no finite solution.
std::optional<Eigen::Isometry3d> solve_point_to_plane(const PointToPlaneSystem& system);

// J^T W J of point-to-point pairs (3 residuals each) for a motion about their weighted source
// mean: [[tr(S) I - S, 0], [0, sum w I]] with S = sums.source_scatter.
se3::Matrix6d point_to_point_hessian(const PointToPointSums& sums);

// A Hessian for the motion about `pivot` in the target frame, T' = T(pivot) exp(x) T(-pivot) T,
// re-expressed for the right perturbation T' = T exp(xi) of the source-to-target transform T:
// H_xi = M^T H M with M = Ad(T(-pivot) T). Tangent order (omega, v), as in core/se3.hpp.
se3::Matrix6d to_right_perturbation(const se3::Matrix6d& hessian_about_pivot,
                                    const Eigen::Vector3d& pivot,
                                    const Eigen::Isometry3d& source_to_target);

// How well the pairs constrain each direction of motion. The Hessian about the pairs' centre is
// balanced (rotations scaled by a length L with equal rotation and translation traces, so a
// rotation omega counts as a displacement L omega) and normalised to mean eigenvalue 1.
struct DegeneracyReport {
  bool degenerate = true;  // smallest / largest eigenvalue < min_eigenvalue_ratio
  se3::Vector6d eigenvalues = se3::Vector6d::Zero();  // ascending, mean 1 (all 0 without pairs)
  // Unit eigenvector of the smallest eigenvalue, in balanced coordinates (L omega, v): e.g. a
  // corridor along z gives ~(0, 0, 0, 0, 0, +-1), a single plane mixes three weak directions.
  se3::Vector6d weakest_direction = se3::Vector6d::Zero();
  double eigenvalue_ratio = 0;  // smallest / largest
  double rotation_scale = 0;    // L, metres
};

// `hessian_about_centre`: for a motion about (roughly) the centroid of the pairs, in the target
// frame (what the point-to-plane and point-to-point sums give with such a pivot).
DegeneracyReport analyse_degeneracy(const se3::Matrix6d& hessian_about_centre,
                                    double min_eigenvalue_ratio);

}  // namespace kartograf::registration
