#include "kartograf/eval/trajectory_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"

namespace kartograf::eval {

namespace {

Eigen::Matrix3Xd positions(const Trajectory& trajectory) {
  Eigen::Matrix3Xd points(3, trajectory.size());
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    points.col(static_cast<Eigen::Index>(k)) = trajectory[k].pose.translation();
  }
  return points;
}

void require_matched(const MatchedPoses& poses, const std::string& what) {
  require(poses.ground_truth.size() == poses.estimate.size(),
          what + ": " + std::to_string(poses.ground_truth.size()) + " ground-truth poses but " +
              std::to_string(poses.estimate.size()) + " estimated ones; match them first");
}

// Rotation angle of R in degrees; atan2 keeps precision near 0 and 180 where acos loses it.
double rotation_angle_deg(const Eigen::Matrix3d& r) {
  const Eigen::Vector3d axis_times_sine(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
  return std::atan2(0.5 * axis_times_sine.norm(), 0.5 * (r.trace() - 1.0)) * 180.0 /
         std::numbers::pi;
}

// The ground truth's motion from pose i to pose j, its translation divided by `scale` (ground
// truth per estimate: in the estimate's units).
Eigen::Isometry3d true_motion(const MatchedPoses& poses, std::size_t i, std::size_t j,
                              double scale = 1) {
  Eigen::Isometry3d motion = poses.ground_truth[i].pose.inverse() * poses.ground_truth[j].pose;
  motion.translation() /= scale;
  return motion;
}

// E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j): the estimate's motion from pose i to j against the truth's.
Eigen::Isometry3d motion_error(const MatchedPoses& poses, std::size_t i, std::size_t j,
                               double scale = 1) {
  return true_motion(poses, i, j, scale).inverse() *
         (poses.estimate[i].pose.inverse() * poses.estimate[j].pose);
}

// The (i, j) pairs delta apart, as documented in the header.
std::vector<std::pair<std::size_t, std::size_t>> rpe_pairs(const MatchedPoses& poses,
                                                           const RpeParams& options) {
  const std::size_t n = poses.size();
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  if (options.unit == DeltaUnit::frames) {
    require(
        std::isfinite(options.delta) && options.delta >= 1 &&
            std::floor(options.delta) == options.delta,
        "RPE: a delta in frames must be a whole number >= 1, got " + std::to_string(options.delta));
    const auto delta = static_cast<std::size_t>(options.delta);
    for (std::size_t i = 0; i + delta < n; ++i) pairs.emplace_back(i, i + delta);
    return pairs;
  }
  require(std::isfinite(options.delta) && options.delta > 0,
          "RPE: a delta in seconds must be > 0, got " + std::to_string(options.delta));
  std::vector<double> times(n);
  for (std::size_t k = 0; k < n; ++k) {
    times[k] = poses.ground_truth[k].timestamp;
    // Not require(): its message would be built, reading times[k - 1], for k == 0 too.
    if (k > 0 && !(times[k] > times[k - 1])) {
      throw Error("RPE: ground-truth timestamps must increase for a delta in seconds; pose " +
                  std::to_string(k) + " has t = " + std::to_string(times[k]) + " after " +
                  std::to_string(times[k - 1]));
    }
  }
  constexpr double kClockSlack = 1e-6;  // s; so that t_i + delta == t_last survives rounding
  for (std::size_t i = 0; i < n; ++i) {
    const double target = times[i] + options.delta;
    if (target > times.back() + kClockSlack) break;
    auto j = static_cast<std::size_t>(std::lower_bound(times.begin(), times.end(), target) -
                                      times.begin());
    if (j == n || (j > 0 && target - times[j - 1] <= times[j] - target)) --j;
    if (j > i) pairs.emplace_back(i, j);
  }
  return pairs;
}

}  // namespace

MatchedPoses match_frames(std::span<const std::optional<Eigen::Isometry3d>> ground_truth,
                          std::span<const Eigen::Isometry3d> estimate) {
  MatchedPoses matched;
  for (std::size_t i = 0; i < ground_truth.size() && i < estimate.size(); ++i) {
    if (!ground_truth[i]) continue;
    const double t = static_cast<double>(i);
    matched.ground_truth.push_back({t, *ground_truth[i]});
    matched.estimate.push_back({t, estimate[i]});
  }
  return matched;
}

MatchedPoses match_poses(const Trajectory& ground_truth, const Trajectory& estimate,
                         std::span<const std::pair<std::size_t, std::size_t>> pairs) {
  MatchedPoses matched;
  matched.ground_truth.reserve(pairs.size());
  matched.estimate.reserve(pairs.size());
  for (const auto& [gt_index, estimate_index] : pairs) {
    require(gt_index < ground_truth.size() && estimate_index < estimate.size(),
            "match_poses: pair (" + std::to_string(gt_index) + ", " +
                std::to_string(estimate_index) +
                ") is out of range: " + std::to_string(ground_truth.size()) + " ground-truth and " +
                std::to_string(estimate.size()) + " estimated poses");
    matched.ground_truth.push_back(ground_truth[gt_index]);
    matched.estimate.push_back(estimate[estimate_index]);
  }
  return matched;
}

ErrorStatistics summarize_errors(std::vector<double> errors) {
  ErrorStatistics stats;
  stats.count = errors.size();
  if (errors.empty()) return stats;
  std::sort(errors.begin(), errors.end());
  const double n = static_cast<double>(errors.size());
  double sum = 0, sum_squares = 0;
  for (double e : errors) {
    sum += e;
    sum_squares += e * e;
  }
  stats.mean = sum / n;
  stats.rmse = std::sqrt(sum_squares / n);
  double squared_deviations = 0;
  for (double e : errors) squared_deviations += (e - stats.mean) * (e - stats.mean);
  stats.std_dev = std::sqrt(squared_deviations / n);
  const std::size_t middle = errors.size() / 2;
  stats.median =
      errors.size() % 2 == 1 ? errors[middle] : 0.5 * (errors[middle - 1] + errors[middle]);
  stats.min = errors.front();
  stats.max = errors.back();
  return stats;
}

SimilarityTransform align_positions(const MatchedPoses& poses, Alignment alignment) {
  require_matched(poses, "trajectory alignment");
  if (alignment == Alignment::none) return {};
  const char* name = alignment == Alignment::sim3 ? "Sim(3)" : "SE(3)";
  require(poses.size() >= 3, std::string("trajectory alignment: ") + name +
                                 " needs >= 3 matched poses, got " + std::to_string(poses.size()));
  const Eigen::Matrix3Xd estimate = positions(poses.estimate);
  const Eigen::Matrix3Xd ground_truth = positions(poses.ground_truth);
  if (alignment == Alignment::sim3) {
    const double spread = (estimate.colwise() - estimate.rowwise().mean()).squaredNorm();
    require(spread > 0,
            "trajectory alignment: Sim(3) needs estimated positions that are not all "
            "the same (the scale is undefined)");
  }
  const Eigen::Matrix4d t = Eigen::umeyama(estimate, ground_truth, alignment == Alignment::sim3);
  SimilarityTransform transform;
  transform.scale = alignment == Alignment::sim3 ? t.block<3, 1>(0, 0).norm() : 1.0;
  transform.rotation = t.block<3, 3>(0, 0) / transform.scale;
  transform.translation = t.block<3, 1>(0, 3);
  return transform;
}

Trajectory transform_trajectory(const Trajectory& trajectory,
                                const SimilarityTransform& transform) {
  Trajectory moved = trajectory;
  for (StampedPose& stamped : moved) {
    const Eigen::Vector3d position =
        transform.scale * (transform.rotation * stamped.pose.translation()) + transform.translation;
    const Eigen::Matrix3d orientation = transform.rotation * stamped.pose.rotation();
    stamped.pose.linear() = orientation;
    stamped.pose.translation() = position;
  }
  return moved;
}

AteResult compute_ate(const MatchedPoses& poses, Alignment alignment) {
  AteResult result;
  result.alignment = align_positions(poses, alignment);
  const Eigen::Matrix3Xd estimate = positions(poses.estimate);
  const Eigen::Matrix3Xd aligned =
      (result.alignment.scale * (result.alignment.rotation * estimate)).colwise() +
      result.alignment.translation;
  const Eigen::Matrix3Xd residuals = positions(poses.ground_truth) - aligned;
  std::vector<double> errors(poses.size());
  for (std::size_t k = 0; k < errors.size(); ++k) {
    errors[k] = residuals.col(static_cast<Eigen::Index>(k)).norm();
  }
  result.translation_m = summarize_errors(errors);
  result.errors_m = std::move(errors);
  return result;
}

RpeResult compute_rpe(const MatchedPoses& poses, const RpeParams& options) {
  require_matched(poses, "RPE");
  const auto pairs = rpe_pairs(poses, options);
  require(!pairs.empty(), "RPE: no pose pair is " + std::to_string(options.delta) +
                              (options.unit == DeltaUnit::frames ? " frames" : " s") +
                              " apart among " + std::to_string(poses.size()) + " matched poses");
  std::vector<double> translation(pairs.size()), rotation(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    const Eigen::Isometry3d error = motion_error(poses, i, j);
    translation[k] = error.translation().norm();
    rotation[k] = rotation_angle_deg(error.linear());
  }
  return {summarize_errors(std::move(translation)), summarize_errors(std::move(rotation))};
}

namespace {

// The estimate re-chained from its first pose, with the steps ending at `true_steps` (sorted)
// taken from the ground truth, in the estimate's units (`scale`: the alignment's, ground truth
// per estimate).
MatchedPoses with_true_steps(const MatchedPoses& poses, std::span<const std::size_t> true_steps,
                             double scale) {
  MatchedPoses result = poses;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Eigen::Isometry3d step =
        std::binary_search(true_steps.begin(), true_steps.end(), k)
            ? true_motion(poses, k - 1, k, scale)
            : poses.estimate[k - 1].pose.inverse() * poses.estimate[k].pose;
    result.estimate[k].pose = result.estimate[k - 1].pose * step;
  }
  return result;
}

}  // namespace

WorstSteps worst_steps(const MatchedPoses& poses, std::size_t count, Alignment alignment) {
  require_matched(poses, "worst steps");
  require(poses.size() >= 3,
          "worst steps: need at least 3 matched poses, got " + std::to_string(poses.size()));
  WorstSteps result;
  const AteResult as_estimated = compute_ate(poses, alignment);
  result.ate_rmse_m = as_estimated.translation_m.rmse;
  const double scale = as_estimated.alignment.scale;
  std::vector<StepError> steps(poses.size() - 1);
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Eigen::Isometry3d error = motion_error(poses, k - 1, k, scale);
    steps[k - 1] = {k, poses.estimate[k].timestamp, error.translation().norm(),
                    rotation_angle_deg(error.linear()), 0};
  }
  const auto larger = [](const StepError& a, const StepError& b) {
    return a.translation_m > b.translation_m;
  };
  count = std::min(count, steps.size());
  std::partial_sort(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(count), steps.end(),
                    larger);
  steps.resize(count);
  std::vector<std::size_t> all;
  for (StepError& step : steps) {
    const std::size_t one[] = {step.pose};
    step.ate_rmse_with_true_step_m =
        compute_ate(with_true_steps(poses, one, scale), alignment).translation_m.rmse;
    all.push_back(step.pose);
  }
  std::sort(all.begin(), all.end());
  result.ate_rmse_with_true_steps_m =
      compute_ate(with_true_steps(poses, all, scale), alignment).translation_m.rmse;
  result.steps = std::move(steps);
  return result;
}

TrajectoryEvaluation evaluate_trajectory(const MatchedPoses& poses, Alignment alignment,
                                         const RpeParams& rpe_options) {
  TrajectoryEvaluation evaluation;
  evaluation.ate = compute_ate(poses, alignment);
  MatchedPoses aligned{poses.ground_truth,
                       transform_trajectory(poses.estimate, evaluation.ate.alignment)};
  evaluation.rpe = compute_rpe(aligned, rpe_options);
  return evaluation;
}

}  // namespace kartograf::eval
