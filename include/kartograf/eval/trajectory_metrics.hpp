#pragma once
// Trajectory accuracy as the TUM RGB-D benchmark defines it (J. Sturm et al., "A benchmark for the
// evaluation of RGB-D SLAM systems", IROS 2012, and its tools evaluate_ate.py / evaluate_rpe.py).
//
// Everything works on matched poses: ground_truth[k] and estimate[k] are the same instant. Match
// by timestamp with io::associate_timestamps (TUM associate.py's rule: nearest within a maximum
// difference, closest pairs first, each pose used once), then match_poses().
//
// ATE: the estimate's positions are aligned to the ground truth's by least squares (Umeyama 1991:
//   SE(3) = Horn's method, what evaluate_ate.py does; Sim(3) also fits a scale, for monocular
//   estimates), then per pose |x_gt - (s R x_est + t)|.
// RPE: for every pair (i, j) delta apart, E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q the ground truth
//   and P the estimate; translational error |trans(E)| [m], rotational error
//   acos((trace(rot(E)) - 1) / 2) [deg], summarised over all pairs (evaluate_rpe.py --fixed_delta
//   with all pairs). Pairs are taken over the matched list:
//   - frames: j = i + delta;
//   - seconds: j = the pose whose ground-truth time is nearest to t_i + delta, for every i with
//     t_i + delta <= t_last. (evaluate_rpe.py drops every pair ending at the last pose, a slip that
//     also drops the genuine last one; it looks ground truth up per estimate pose instead of
//     matching first, as evo does.)
//   With Sim(3) alignment, RPE is measured on the scaled estimate; a rigid alignment does not
//   change relative motion.
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kartograf/core/trajectory.hpp"

namespace kartograf::eval {

// ground_truth[k] and estimate[k] are the same instant.
struct MatchedPoses {
  Trajectory ground_truth;
  Trajectory estimate;
  std::size_t size() const { return ground_truth.size(); }
};

// pairs: (ground-truth index, estimate index), e.g. from io::associate_timestamps(gt times,
// estimate times, max_difference). Throws Error on an index out of range.
MatchedPoses match_poses(const Trajectory& ground_truth, const Trajectory& estimate,
                         std::span<const std::pair<std::size_t, std::size_t>> pairs);

// Frame k of the estimate against frame k of the ground truth, for the frames that have a
// ground-truth pose (a data set's poses per frame); timestamps are the frame numbers.
MatchedPoses match_frames(std::span<const std::optional<Eigen::Isometry3d>> ground_truth,
                          std::span<const Eigen::Isometry3d> estimate);

// count, RMSE, mean, median, population standard deviation, min and max of a list of errors.
struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0, mean = 0, median = 0, std_dev = 0, min = 0, max = 0;
};
ErrorStatistics summarize_errors(std::vector<double> errors);  // all zero when empty

enum class Alignment { none, se3, sim3 };

// x_ground_truth ≈ scale * rotation * x_estimate + translation.
struct SimilarityTransform {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1;
};

// Least squares over the matched positions; identity for Alignment::none. SE(3) and Sim(3) need
// at least 3 poses, Sim(3) estimate positions that are not all the same.
SimilarityTransform align_positions(const MatchedPoses& poses, Alignment alignment);

// Poses moved by a similarity: position s R x + t, orientation R R_i.
Trajectory transform_trajectory(const Trajectory& trajectory, const SimilarityTransform& transform);

struct AteResult {
  SimilarityTransform alignment;
  ErrorStatistics translation_m;
  std::vector<double> errors_m;  // per matched pose, in order: what translation_m summarises
};
AteResult compute_ate(const MatchedPoses& poses, Alignment alignment);

enum class DeltaUnit { frames, seconds };

struct RpeParams {
  double delta = 1;  // frames (a positive whole number) or seconds (> 0)
  DeltaUnit unit = DeltaUnit::frames;
};

struct RpeResult {
  ErrorStatistics translation_m;
  ErrorStatistics rotation_deg;
};
// Throws Error when no pair is delta apart (or, for seconds, the timestamps are not increasing).
RpeResult compute_rpe(const MatchedPoses& poses, const RpeParams& options);

// The steps that carry a trajectory's error. A step is the motion between consecutive matched
// poses (pose - 1 -> pose), its error that of an RPE pair one frame apart. For the `count` steps
// with the largest translation error (largest first): the ATE RMSE the estimate would have with
// that step alone taken from the ground truth and every other step as estimated (chained from the
// first pose, aligned as `alignment`), and with all of them at once. A few wrong steps (a lost
// frame, a wrong basin) show as an ATE that falls to a fraction; drift spread over every step as
// one that barely moves. Errors may cancel: one step taken from the ground truth alone can raise
// the ATE. With Alignment::sim3 the steps are compared, and taken, in the ground truth's units
// divided by the alignment's scale (the estimate's). Throws Error on fewer than 3 matched poses.
struct StepError {
  std::size_t pose = 0;  // matched index of the step's end
  double timestamp = 0;  // the estimate's, at the step's end
  double translation_m = 0;
  double rotation_deg = 0;
  double ate_rmse_with_true_step_m = 0;
};
struct WorstSteps {
  std::vector<StepError> steps;
  double ate_rmse_m = 0;                  // as estimated
  double ate_rmse_with_true_steps_m = 0;  // with all of `steps` from the ground truth
};
WorstSteps worst_steps(const MatchedPoses& poses, std::size_t count, Alignment alignment);

// ATE with the given alignment, and RPE on the estimate that alignment moved.
struct TrajectoryEvaluation {
  AteResult ate;
  RpeResult rpe;
};
TrajectoryEvaluation evaluate_trajectory(const MatchedPoses& poses, Alignment alignment,
                                         const RpeParams& rpe_options);

}  // namespace kartograf::eval
