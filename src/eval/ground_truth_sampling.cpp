#include "kartograf/eval/ground_truth_sampling.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"

namespace kartograf::eval {

namespace {

// same[k]: step k (pose k-1 -> k) equals step k-1; false for k < 2.
std::vector<bool> repeated_steps(const Trajectory& truth, const GroundTruthSamplingParams& p) {
  std::vector<bool> same(truth.size(), false);
  const auto step = [&](std::size_t k) { return truth[k - 1].pose.inverse() * truth[k].pose; };
  for (std::size_t k = 2; k < truth.size(); ++k) {
    const Eigen::Isometry3d difference = step(k - 1).inverse() * step(k);
    const double degrees =
        Eigen::AngleAxisd(difference.linear()).angle() * 180.0 / std::numbers::pi;
    same[k] = difference.translation().norm() < p.step_tolerance_m &&
              std::abs(degrees) < p.step_tolerance_deg;
  }
  return same;
}

// Whether the poses `offset`, offset + period, ... are the measured ones: every step inside a
// run repeats the one before, and at least half of the runs (min_runs at least) change.
bool fits(const std::vector<bool>& same, std::size_t period, std::size_t offset,
          const GroundTruthSamplingParams& p) {
  std::size_t runs = 0, changes = 0;
  for (std::size_t k = 2; k < same.size(); ++k) {
    const bool run_starts = (k - 1) % period == offset;  // step k leaves a measured pose
    if (!run_starts && !same[k]) return false;
    if (run_starts) ++runs, changes += !same[k];
  }
  return runs >= p.min_runs && 2 * changes >= runs;
}

}  // namespace

GroundTruthSampling ground_truth_sampling(const MatchedPoses& poses,
                                          const GroundTruthSamplingParams& params) {
  require(poses.ground_truth.size() == poses.estimate.size(),
          "ground_truth_sampling: " + std::to_string(poses.ground_truth.size()) +
              " ground-truth poses but " + std::to_string(poses.estimate.size()) +
              " estimated ones; match them first");
  GroundTruthSampling sampling;
  const std::vector<bool> same = repeated_steps(poses.ground_truth, params);
  for (std::size_t period = 2; period <= params.max_period; ++period) {
    for (std::size_t offset = 0; offset < period; ++offset) {
      if (!fits(same, period, offset, params)) continue;
      sampling.period = period;
      for (std::size_t k = offset; k < poses.size(); k += period) sampling.measured.push_back(k);
      return sampling;
    }
  }
  for (std::size_t k = 0; k < poses.size(); ++k) sampling.measured.push_back(k);
  return sampling;
}

MatchedPoses select_poses(const MatchedPoses& poses, const std::vector<std::size_t>& indices) {
  MatchedPoses selected;
  for (const std::size_t k : indices) {
    require(k < poses.size(), "select_poses: index " + std::to_string(k) + " of " +
                                  std::to_string(poses.size()) + " matched poses");
    selected.ground_truth.push_back(poses.ground_truth[k]);
    selected.estimate.push_back(poses.estimate[k]);
  }
  return selected;
}

std::optional<MeasuredPoseAte> ate_at_measured_poses(const MatchedPoses& poses) {
  const GroundTruthSampling sampling = ground_truth_sampling(poses);
  if (!sampling.interpolated() || sampling.measured.size() < 3) return std::nullopt;
  return MeasuredPoseAte{sampling.period,
                         compute_ate(select_poses(poses, sampling.measured), Alignment::se3)};
}

}  // namespace kartograf::eval
