#include "kartograf/registration/heading_prior.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace kartograf::registration {

namespace {

constexpr double kKeep = 0.95;  // decay per learned step: about the last 20 steps

constexpr double kVarianceFloor = 1e-12;  // m^2: a spread of nothing is no reason to divide by 0

constexpr double kLeastTurn =
    2.0 * std::numbers::pi / 180.0;  // radians: a step's turn that shows its axis

}  // namespace

Eigen::Vector3d untwisted(const Eigen::Isometry3d& step) {
  const Eigen::AngleAxisd turn(step.linear());
  return Eigen::AngleAxisd(-0.5 * turn.angle(), turn.axis()) * step.translation();
}

Eigen::Vector3d travel_on_arc(const Eigen::Vector3d& heading, const Eigen::Isometry3d& step) {
  const Eigen::AngleAxisd turn(step.linear());
  return Eigen::AngleAxisd(0.5 * turn.angle(), turn.axis()) * heading.normalized();
}

void HeadingPrior::learn(const Eigen::Isometry3d& step) {
  const Eigen::Vector3d travel = untwisted(step);
  if (heading_.squaredNorm() > 0) {
    const Eigen::Vector3d along = heading_.normalized();
    across_squared_ =
        kKeep * across_squared_ + (1 - kKeep) * (travel - travel.dot(along) * along).squaredNorm();
    weight_ = kKeep * weight_ + (1 - kKeep);
  }
  // Weighted by its length: short steps are mostly noise.
  heading_ = kKeep * heading_ + (1 - kKeep) * travel;
  // Weighted by its angle, left and right turns alike: small turns are mostly noise.
  const Eigen::AngleAxisd turn(step.linear());
  if (turn.angle() > kLeastTurn) {
    const double side = turn_axis_.dot(turn.axis()) < 0 ? -1.0 : 1.0;
    turn_axis_ = kKeep * turn_axis_ + (1 - kKeep) * side * turn.angle() * turn.axis();
  }
}

Eigen::Vector3d HeadingPrior::turn_axis() const {
  if (turn_axis_.squaredNorm() == 0) return Eigen::Vector3d::Zero();
  return turn_axis_.normalized();
}

Eigen::Vector3d HeadingPrior::travel_on(const Eigen::Isometry3d& step) const {
  if (heading_.squaredNorm() == 0) return Eigen::Vector3d::Zero();
  return travel_on_arc(heading_, step);
}

std::vector<Eigen::Isometry3d> HeadingPrior::steps_around(const Eigen::Isometry3d& step,
                                                          const HeadingStepGrid& grid) const {
  std::vector<Eigen::Isometry3d> steps;
  if (heading_.squaredNorm() == 0 || grid.length_spacing <= 0) return steps;
  // Whole spacings that fit, a rounding error short of one still counting.
  const auto fitting = [](double range, double spacing) {
    return static_cast<int>(std::floor(range / spacing + 1e-9));
  };
  const int turns = grid.turn_spacing > 0 ? fitting(grid.max_turn, grid.turn_spacing) : 0;
  const int lengths = fitting(grid.longest - grid.shortest, grid.length_spacing);
  for (int t = -turns; t <= turns; ++t) {
    Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
    turned.linear() =
        step.linear() * Eigen::AngleAxisd(t * grid.turn_spacing, grid.turn_axis).toRotationMatrix();
    const Eigen::Vector3d travel = (grid.backwards ? -1.0 : 1.0) * travel_on(turned);
    for (int l = 0; l <= lengths; ++l) {
      turned.translation() = (grid.shortest + l * grid.length_spacing) * travel;
      steps.push_back(turned);
    }
  }
  return steps;
}

bool HeadingPrior::ready() const {
  static const double kTwentySteps = 1 - std::pow(kKeep, 20);
  return weight_ >= kTwentySteps && heading_.squaredNorm() > 0;
}

double HeadingPrior::across_variance() const {
  return weight_ > 0 ? across_squared_ / weight_ : 0.0;
}

se3::Matrix6d HeadingPrior::information(const Eigen::Isometry3d& step) const {
  se3::Matrix6d information = se3::Matrix6d::Zero();
  if (!ready()) return information;
  const Eigen::Vector3d along = travel_on(step);
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - along * along.transpose();
  // The translation moves by R v under the right perturbation (omega, v).
  const Eigen::Matrix3d jacobian = across * step.linear();
  information.bottomRightCorner<3, 3>() =
      jacobian.transpose() * jacobian / std::max(across_variance(), kVarianceFloor);
  return information;
}

Eigen::Isometry3d HeadingPrior::combine(const Eigen::Isometry3d& step,
                                        const se3::Matrix6d& measured) const {
  if (!ready()) return step;
  const se3::Matrix6d prior = information(step);
  const Eigen::Vector3d along = travel_on(step);
  const Eigen::Vector3d across = step.translation() - step.translation().dot(along) * along;
  se3::Vector6d gradient = se3::Vector6d::Zero();
  gradient.tail<3>() =
      step.linear().transpose() * across / std::max(across_variance(), kVarianceFloor);
  se3::Matrix6d system = measured + prior;
  // Directions neither side measures (a free turn) get a negligible ridge and stay put.
  system.diagonal().array() += 1e-12 * system.trace() + 1e-300;
  const se3::Vector6d xi = -system.ldlt().solve(gradient);
  if (!xi.allFinite()) return step;
  return step * se3::exp(xi);
}

}  // namespace kartograf::registration
