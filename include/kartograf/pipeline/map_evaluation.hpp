#pragma once
// A map pipeline's result scored against ground truth: the trajectory (ATE after an SE(3)
// alignment, RPE over one frame), and, where a floor plan is known, the rooms (ipa recall and
// precision, MAORIS MCC: eval/room_metrics.hpp) and the grid's classes (per-class IoU:
// eval/semantic_metrics.hpp). The ATE's alignment carries the map frame into the ground truth's
// world frame; our rooms and classes are read at the centre of every plan cell.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/eval/ground_truth_sampling.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"

namespace kartograf::pipeline {

struct MapGroundTruth {
  std::vector<std::optional<Eigen::Isometry3d>> poses;  // per frame, camera-to-world
  // The floor plan in the world frame (z up, floor at z = 0); rooms and classes on its grid
  // (rooms 0: none; classes unknown: not scored). Empty when the data set has none.
  std::optional<OccupancyGrid> plan;
  LabelImage rooms;
  SemanticImage classes;
};

// One frame that has a ground-truth pose, after the ATE's alignment.
struct FrameTrajectoryError {
  std::size_t frame = 0;
  double error_m = 0;                    // |true position - aligned estimate|
  Eigen::Vector3d true_position_in_map;  // the true camera position carried into the map frame
};

struct MapEvaluation {
  std::optional<eval::TrajectoryEvaluation> trajectory;
  // The odometry's own trajectory (before loop closure), scored the same way: what the back end
  // adds is the difference.
  std::optional<eval::TrajectoryEvaluation> odometry_trajectory;
  // Both again at the ground truth's measured poses alone, where it interpolates the others
  // (SUN3D's every 5th frame; eval/ground_truth_sampling.hpp).
  std::optional<eval::MeasuredPoseAte> trajectory_at_measured_poses, odometry_at_measured_poses;
  std::vector<FrameTrajectoryError> frame_errors;  // in frame order; empty without a trajectory
  std::optional<eval::RoomSegmentationScores> rooms;
  std::optional<eval::SemanticScores> semantic;
  // Ours at the plan's cells (rooms 0: none; classes unknown: unobserved), beside the truth.
  LabelImage rooms_on_plan, true_rooms;
  SemanticImage classes_on_plan, true_classes;
  std::vector<std::string> skipped;  // what could not be scored, and why
};

// Throws Error when the plan's images do not match its grid.
MapEvaluation evaluate_map(const MapPipelineResult& result, const MapGroundTruth& truth);

}  // namespace kartograf::pipeline
