#pragma once
// Which ground-truth poses were measured. Some references measure one pose in every N and fill the
// rest in at constant velocity: SUN3D's reconstruction as the 3DMatch fragments ship it (every 5th
// frame; ../shared/data/sun3d_studyroom_fragment1: each run of five steps is one step five times,
// to 1e-4, and the runs differ by 4-19 mm). An estimate that follows the camera's real motion
// between two measured poses is then scored against the interpolation there, so the ATE over
// every pose mixes the estimate's error with the reference's; the ATE over the measured poses does
// not.
//
// Found by the steps alone: with period N, every step inside a run of N equals the step before it
// (within the tolerances), and most runs differ from the one before. A robot driving at constant
// velocity repeats its steps too, but in runs of no fixed length, and a reference measured at
// every pose has no period: period 1.
#include <cstddef>
#include <optional>
#include <vector>

#include "kartograf/eval/trajectory_metrics.hpp"

namespace kartograf::eval {

struct GroundTruthSamplingParams {
  double step_tolerance_m = 0.0005;  // two steps whose translations differ by less are the same
  double step_tolerance_deg = 0.03;  // ... and whose rotations differ by less
  std::size_t max_period = 10;
  // At least this many runs, and at least half of them a change from the run before: what tells
  // a measuring period from a constant velocity.
  std::size_t min_runs = 3;
};

struct GroundTruthSampling {
  std::size_t period = 1;             // 1: every pose measured
  std::vector<std::size_t> measured;  // matched indices of the measured poses, increasing
  bool interpolated() const { return period > 1; }
};

// Throws Error when the ground truth and the estimate are not matched (equal sizes).
GroundTruthSampling ground_truth_sampling(const MatchedPoses& poses,
                                          const GroundTruthSamplingParams& params = {});

// The matched poses at `indices` only (e.g. GroundTruthSampling::measured).
MatchedPoses select_poses(const MatchedPoses& poses, const std::vector<std::size_t>& indices);

// The ATE (SE(3) alignment) over the measured poses alone, where the ground truth interpolates the
// others and measured at least 3; nullopt where it measured every pose or too few.
struct MeasuredPoseAte {
  std::size_t period = 1;
  AteResult ate;  // ate.translation_m.count: the measured poses
};
std::optional<MeasuredPoseAte> ate_at_measured_poses(const MatchedPoses& poses);

}  // namespace kartograf::eval
