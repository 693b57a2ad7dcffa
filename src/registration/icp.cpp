#include "kartograf/registration/icp.hpp"

#include <cmath>
#include <string>

#include "kartograf/registration/projective_association.hpp"
#include "kartograf/registration/rigid_solvers.hpp"

namespace kartograf::registration {

std::vector<IcpLevelParams> odometry_levels() {
  // The coarse gate is wide: a 5 degree turn moves points 3 m away by 26 cm, and a gate below
  // the initial error keeps only the surfaces that already agree (the estimate then slides
  // along them). Full resolution uses the M3 paper's 1 point in 10. Tuned on synthetic 640x480
  // frames (bench/icp_bench.cpp): 2-4 iterations per level up to 6 cm and 5 degrees per frame.
  // 1 in 2 at 160x120 still leaves ~9,000 points for the coarse alignment.
  //      iterations, 1-in-k, max distance, robust scale
  return {{4, 10, 0.03, 0.01}, {6, 4, 0.10, 0.03}, {10, 2, 0.30, 0.10}};
}

struct IcpEngine::LastSums {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // where the pairs were taken
  std::optional<PointToPlaneSystem> plane;
  std::optional<PointToPointSums> point;
};

struct IcpEngine::LevelOutcome {
  int iterations = 0;
  bool converged = false;
  std::optional<LastSums> last;  // of the last iteration
};

namespace {

void validate(const IcpParams& params) {
  require(!params.levels.empty(), "ICP: at least one level is required");
  for (std::size_t i = 0; i < params.levels.size(); ++i) {
    const IcpLevelParams& level = params.levels[i];
    const std::string where = "ICP level " + std::to_string(i) + ": ";
    require(level.max_iterations >= 0, where + "max_iterations must be >= 0");
    require(level.subsample >= 1, where + "subsample must be >= 1");
    require(level.search_radius >= 0 && level.search_radius <= 16,
            where + "search_radius must be 0..16");
    require(std::isfinite(level.max_distance) && level.max_distance > 0,
            where + "max_distance must be finite and > 0");
    require(params.robust_kernel == RobustKernel::none ||
                (std::isfinite(level.robust_scale) && level.robust_scale > 0),
            where + "robust_scale must be finite and > 0");
  }
  require(!std::isnan(params.max_normal_angle_deg) && params.max_normal_angle_deg >= 0,
          "ICP: max_normal_angle_deg must be >= 0");
  require(
      params.convergence.rotation_tolerance >= 0 && params.convergence.translation_tolerance >= 0,
      "ICP: convergence tolerances must be >= 0");
  require(params.min_eigenvalue_ratio >= 0 && params.min_eigenvalue_ratio <= 1,
          "ICP: min_eigenvalue_ratio must be in [0, 1]");
}

// Keeps the rotation orthonormal over many composed updates.
Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& pose) {
  Eigen::Isometry3d result = pose;
  result.linear() = Eigen::Quaterniond(pose.linear()).normalized().toRotationMatrix();
  return result;
}

// Adds the prior's cost to a point-to-plane system linearised at `pose`. The solver's update is
// D = T(pivot) exp(x) T(pivot)^-1 applied on the left, so e(D T) ~ e(T) + A x with
// A = Ad(T^-1 T(pivot)).
void add_prior(const IcpPrior& prior, const Eigen::Isometry3d& pose, PointToPlaneSystem& system) {
  const se3::Matrix6d information = system.weight_sum * prior.information;
  const Eigen::Isometry3d to_pivot(Eigen::Translation3d(system.pivot));
  const se3::Matrix6d a = se3::adjoint(pose.inverse() * to_pivot);
  const se3::Vector6d error = se3::log(prior.mean.inverse() * pose);
  system.jtj.noalias() += a.transpose() * information * a;
  system.jtr.noalias() += a.transpose() * (information * error);
}

}  // namespace

IcpEngine::IcpEngine(const compute::Context& context, IcpParams params,
                     std::unique_ptr<CorrespondenceFinder> finder)
    : params_(std::move(params)),
      finder_(finder ? std::move(finder) : std::make_unique<ProjectiveAssociation>(context)),
      reduction_(context) {
  validate(params_);
}

void IcpEngine::set_max_distance(std::size_t level, double metres) {
  require(level < params_.levels.size(), "icp: set_max_distance: no level " +
                                             std::to_string(level) + " of " +
                                             std::to_string(params_.levels.size()));
  require(std::isfinite(metres) && metres > 0,
          "icp: set_max_distance: the gate must be finite and > 0, got " + std::to_string(metres));
  params_.levels[level].max_distance = metres;
}

AssociationParams IcpEngine::gates_of(int level) const {
  const IcpLevelParams& lp = params_.levels[static_cast<std::size_t>(level)];
  return {lp.max_distance, params_.max_normal_angle_deg, lp.subsample, lp.search_radius};
}

Correspondences IcpEngine::pairs_of(int level, const CloudView& source, const CloudView& target,
                                    const Eigen::Isometry3d& pose) const {
  const CorrespondenceBuffers& buffers = buffers_[static_cast<std::size_t>(level)];
  const IcpLevelParams& lp = params_.levels[static_cast<std::size_t>(level)];
  Correspondences pairs;
  pairs.source = source.points;
  pairs.target = target.points;
  pairs.target_normals = target.normals;
  pairs.correspondences = &buffers.target_index;
  pairs.weights = buffers.weights.empty() ? nullptr : &buffers.weights;
  pairs.source_to_target = pose;
  pairs.max_distance = lp.max_distance;
  pairs.robust = {params_.robust_kernel, lp.robust_scale};
  return pairs;
}

IcpEngine::LevelOutcome IcpEngine::run_level(int level, const CloudView& source,
                                             const CloudView& target,
                                             const Eigen::Vector3d& centroid,
                                             Eigen::Isometry3d& pose, const IcpPrior* prior) {
  LevelOutcome outcome;
  const AssociationParams gates = gates_of(level);
  const int max_iterations = params_.levels[static_cast<std::size_t>(level)].max_iterations;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    finder_->find(source, target, pose, gates, buffers_[static_cast<std::size_t>(level)]);
    const Correspondences pairs = pairs_of(level, source, target, pose);
    const Eigen::Vector3d pivot = pose * centroid;
    outcome.last = LastSums{pose, {}, {}};
    std::optional<Eigen::Isometry3d> delta;
    if (params_.metric == ErrorMetric::point_to_plane) {
      outcome.last->plane = reduction_.point_to_plane(pairs, pivot);
      if (prior) {
        // The prior joins the step only: fitness, RMSE and information stay the pairs' own.
        PointToPlaneSystem with_prior = *outcome.last->plane;
        add_prior(*prior, pose, with_prior);
        delta = solve_point_to_plane(with_prior);
      } else {
        delta = solve_point_to_plane(*outcome.last->plane);
      }
    } else {
      outcome.last->point = reduction_.point_to_point(pairs, pivot, pivot);
      delta = solve_point_to_point(*outcome.last->point);
    }
    if (!delta) break;  // too few pairs: keep the estimate, the level does not converge
    pose = orthonormalized(*delta * pose);
    ++outcome.iterations;
    // The update's size where the points are: its rotation and its motion of the pivot.
    const double rotation = se3::rotation_angle(*delta);
    const double translation = (*delta * pivot - pivot).norm();
    if (rotation < params_.convergence.rotation_tolerance &&
        translation < params_.convergence.translation_tolerance) {
      outcome.converged = true;
      break;
    }
  }
  return outcome;
}

void IcpEngine::evaluate(const CloudView& source, const CloudView& target,
                         const Eigen::Vector3d& centroid, const LevelOutcome& finest,
                         IcpResult& result) {
  // Converged: the last iteration's pairs and sums, taken before an update below the
  // tolerances, stand for the returned transform. Otherwise pair up again at the result.
  LastSums last;
  if (finest.converged && finest.last) {
    last = *finest.last;
  } else {
    last.pose = result.source_to_target;
    finder_->find(source, target, last.pose, gates_of(0), buffers_[0]);
  }
  const Correspondences pairs = pairs_of(0, source, target, last.pose);
  const Eigen::Vector3d pivot = last.pose * centroid;
  if (target.normals && !last.plane) last.plane = reduction_.point_to_plane(pairs, pivot);
  if ((params_.metric == ErrorMetric::point_to_point || !target.normals) && !last.point) {
    last.point = reduction_.point_to_point(pairs, pivot, pivot);
  }
  // The metric's own residuals for fitness and RMSE.
  const bool plane_metric = params_.metric == ErrorMetric::point_to_plane;
  result.considered_count =
      plane_metric ? last.plane->considered_count : last.point->considered_count;
  result.inlier_count = plane_metric ? last.plane->pair_count : last.point->pair_count;
  const double squared = plane_metric ? last.plane->unweighted_squared_error_sum
                                      : last.point->unweighted_squared_error_sum;
  if (result.inlier_count > 0) {
    result.inlier_rmse = std::sqrt(squared / static_cast<double>(result.inlier_count));
  }
  if (result.considered_count > 0) {
    result.fitness =
        static_cast<double>(result.inlier_count) / static_cast<double>(result.considered_count);
  }
  // Point-to-plane J^T J whenever there are normals: sliding along a surface changes no
  // distance to it, whatever the metric (point-to-point pairs would hide that degeneracy).
  const se3::Matrix6d hessian = last.plane ? last.plane->jtj : point_to_point_hessian(*last.point);
  const Eigen::Vector3d hessian_pivot = last.plane ? pivot : last.point->source_mean;
  result.information = to_right_perturbation(hessian, hessian_pivot, result.source_to_target);
  result.degeneracy = analyse_degeneracy(hessian, params_.min_eigenvalue_ratio);
}

IcpResult IcpEngine::align(const FramePyramid& source, const FramePyramid& target,
                           const Eigen::Isometry3d& initial) {
  const std::vector<CloudView> source_levels = source.views();
  const std::vector<CloudView> target_levels = target.views();
  return align(source_levels, target_levels, initial);
}

IcpResult IcpEngine::align(std::span<const CloudView> source_levels,
                           std::span<const CloudView> target_levels,
                           const Eigen::Isometry3d& initial) {
  return align_levels(source_levels, target_levels, initial, nullptr);
}

IcpResult IcpEngine::align(std::span<const CloudView> source_levels,
                           std::span<const CloudView> target_levels,
                           const Eigen::Isometry3d& initial, const IcpPrior& prior) {
  require(prior.mean.matrix().allFinite() && prior.information.allFinite(),
          "ICP: the prior has NaN/Inf entries");
  return align_levels(source_levels, target_levels, initial, &prior);
}

IcpResult IcpEngine::align_levels(std::span<const CloudView> source_levels,
                                  std::span<const CloudView> target_levels,
                                  const Eigen::Isometry3d& initial, const IcpPrior* prior) {
  const std::size_t level_count = params_.levels.size();
  require(source_levels.size() >= level_count && target_levels.size() >= level_count,
          "ICP: " + std::to_string(level_count) + " levels configured but the source has " +
              std::to_string(source_levels.size()) + " and the target " +
              std::to_string(target_levels.size()));
  require(initial.matrix().allFinite(), "ICP: the initial transform has NaN/Inf entries");
  for (std::size_t level = 0; level < level_count; ++level) {
    const std::string where = "ICP level " + std::to_string(level) + ": ";
    require(source_levels[level].points && target_levels[level].points,
            where + "source and target points are required");
    require(params_.metric != ErrorMetric::point_to_plane || target_levels[level].normals,
            where + "point-to-plane needs target normals");
  }
  buffers_.resize(std::max(buffers_.size(), level_count));

  // The pivot of every linearisation: the source centroid (from the coarsest level), moved by
  // the current estimate. Any nearby point works; a central one keeps the systems well scaled.
  Correspondences identity;
  identity.source = identity.target = source_levels[level_count - 1].points;
  const Eigen::Vector3d centroid = reduction_.point_to_point(identity).source_mean;

  IcpResult result;
  result.level_iterations.assign(level_count, 0);
  Eigen::Isometry3d pose = orthonormalized(initial);
  LevelOutcome finest;
  for (int level = static_cast<int>(level_count) - 1; level >= 0; --level) {
    const auto index = static_cast<std::size_t>(level);
    finder_->prepare(target_levels[index], level);
    const LevelOutcome outcome =
        run_level(level, source_levels[index], target_levels[index], centroid, pose, prior);
    result.level_iterations[index] = outcome.iterations;
    result.iterations += outcome.iterations;
    if (level == 0) finest = outcome;
  }
  result.converged = finest.converged;
  result.source_to_target = pose;
  evaluate(source_levels[0], target_levels[0], centroid, finest, result);
  return result;
}

}  // namespace kartograf::registration
