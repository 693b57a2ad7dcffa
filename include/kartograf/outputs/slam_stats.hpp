#pragma once
// `kartograf slam`'s stats.json: the run, ATE before and after the pose graph, timings, every
// verified loop closure, the pose graph, the map and the odometry's per-frame reports.
#include <cstddef>
#include <optional>
#include <string>

#include "kartograf/eval/ground_truth_sampling.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/outputs/odometry_stats.hpp"

namespace kartograf::io {

// Verified loop closures the registration accepted, and those the pose graph then pruned.
struct LoopClosureCounts {
  std::size_t accepted = 0, pruned = 0;
};
LoopClosureCounts count_loop_closures(const mapping::SlamResult& result);

// The trajectories against the ground truth: none without it; the `_at_measured` ones only where
// it interpolates between measured poses (eval/ground_truth_sampling.hpp).
struct SlamAccuracy {
  std::optional<eval::AteResult> slam, odometry;
  std::optional<eval::MeasuredPoseAte> slam_at_measured, odometry_at_measured;
};

// The ATEs are null without ground truth; ends with a newline.
std::string slam_stats_json(const SequenceRunRecord& record, const OpenedSequence& opened,
                            const mapping::SlamParams& params, const mapping::SlamResult& result,
                            const SlamAccuracy& accuracy);

}  // namespace kartograf::io
