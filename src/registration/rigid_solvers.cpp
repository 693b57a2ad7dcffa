#include "kartograf/registration/rigid_solvers.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace kartograf::registration {

std::optional<Eigen::Isometry3d> solve_point_to_point(const PointToPointSums& sums) {
  if (sums.pair_count < 3 || !(sums.weight_sum > 0)) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sums.cross_covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (v * u.transpose()).determinant() < 0 ? -1.0 : 1.0;  // no reflections
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = v * d * u.transpose();
  delta.translation() = sums.target_mean - delta.linear() * sums.source_mean;
  if (!delta.matrix().allFinite()) return std::nullopt;
  return delta;
}

std::optional<Eigen::Isometry3d> solve_point_to_plane(const PointToPlaneSystem& system) {
  if (system.pair_count < 6 || !(system.weight_sum > 0)) return std::nullopt;
  const double damping = 1e-9 * system.jtj.trace() / 6.0;
  const se3::Matrix6d damped = system.jtj + damping * se3::Matrix6d::Identity();
  const se3::Vector6d x = damped.ldlt().solve(-system.jtr);
  if (!x.allFinite()) return std::nullopt;
  const Eigen::Translation3d to_pivot(system.pivot);
  return Eigen::Isometry3d(to_pivot * se3::exp(x) * to_pivot.inverse());
}

se3::Matrix6d point_to_point_hessian(const PointToPointSums& sums) {
  se3::Matrix6d hessian = se3::Matrix6d::Zero();
  const Eigen::Matrix3d& scatter = sums.source_scatter;
  hessian.topLeftCorner<3, 3>() = scatter.trace() * Eigen::Matrix3d::Identity() - scatter;
  hessian.bottomRightCorner<3, 3>() = sums.weight_sum * Eigen::Matrix3d::Identity();
  return hessian;
}

se3::Matrix6d to_right_perturbation(const se3::Matrix6d& hessian_about_pivot,
                                    const Eigen::Vector3d& pivot,
                                    const Eigen::Isometry3d& source_to_target) {
  const se3::Matrix6d m = se3::adjoint(Eigen::Translation3d(-pivot) * source_to_target);
  return m.transpose() * hessian_about_pivot * m;
}

DegeneracyReport analyse_degeneracy(const se3::Matrix6d& hessian_about_centre,
                                    double min_eigenvalue_ratio) {
  DegeneracyReport report;
  const double rotation_trace = hessian_about_centre.topLeftCorner<3, 3>().trace();
  const double translation_trace = hessian_about_centre.bottomRightCorner<3, 3>().trace();
  if (!(translation_trace > 0) || !(rotation_trace > 0) || !hessian_about_centre.allFinite()) {
    return report;
  }
  report.rotation_scale = std::sqrt(rotation_trace / translation_trace);
  se3::Vector6d scale;
  scale << Eigen::Vector3d::Constant(1.0 / report.rotation_scale), Eigen::Vector3d::Ones();
  se3::Matrix6d balanced = scale.asDiagonal() * hessian_about_centre * scale.asDiagonal();
  balanced /= balanced.trace() / 6.0;
  const Eigen::SelfAdjointEigenSolver<se3::Matrix6d> eigen(balanced);
  report.eigenvalues = eigen.eigenvalues();
  report.weakest_direction = eigen.eigenvectors().col(0);
  report.eigenvalue_ratio = std::max(0.0, report.eigenvalues(0)) / report.eigenvalues(5);
  report.degenerate = report.eigenvalue_ratio < min_eigenvalue_ratio;
  return report;
}

}  // namespace kartograf::registration
