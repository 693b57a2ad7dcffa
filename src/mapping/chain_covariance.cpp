#include "kartograf/mapping/chain_covariance.hpp"

#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace {

// The inverse of a step's information, which must be positive definite (the odometry's prior
// keeps every direction of a step measured a little).
se3::Matrix6d step_covariance(const registration::RelativePose& step) {
  const Eigen::SelfAdjointEigenSolver<se3::Matrix6d> eigen(step.information);
  require(eigen.info() == Eigen::Success && eigen.eigenvalues().minCoeff() > 0,
          "chain covariance: the information of step " + std::to_string(step.from) + " -> " +
              std::to_string(step.to) + " is not positive definite");
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
         eigen.eigenvectors().transpose();
}

}  // namespace

se3::Matrix6d chain_covariance(std::span<const registration::RelativePose> steps,
                               std::span<const Eigen::Isometry3d> poses, std::size_t from,
                               std::size_t to) {
  require(from < to && to < poses.size(),
          "chain covariance: frames " + std::to_string(from) + " -> " + std::to_string(to) +
              " are not an increasing pair of the " + std::to_string(poses.size()) + " poses");
  std::vector<const registration::RelativePose*> step_of(to - from, nullptr);
  for (const registration::RelativePose& step : steps) {
    if (step.from + 1 == step.to && step.from >= from && step.to <= to)
      step_of[step.from - from] = &step;
  }
  const Eigen::Isometry3d end_inverse = poses[to].inverse();
  se3::Matrix6d covariance = se3::Matrix6d::Zero();
  for (std::size_t k = from; k < to; ++k) {
    const registration::RelativePose* step = step_of[k - from];
    require(step != nullptr, "chain covariance: no odometry step from frame " + std::to_string(k) +
                                 " to " + std::to_string(k + 1));
    const se3::Matrix6d moved = se3::adjoint(end_inverse * poses[k + 1]);
    covariance += moved * step_covariance(*step) * moved.transpose();
  }
  return covariance;
}

double mahalanobis_squared(const Eigen::Isometry3d& correction, const se3::Matrix6d& covariance) {
  const se3::Vector6d tangent = se3::log(correction);
  return tangent.dot(covariance.ldlt().solve(tangent));
}

}  // namespace kartograf::mapping
