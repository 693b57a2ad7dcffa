#include "kartograf/pipeline/map_evaluation.hpp"

#include "kartograf/core/error.hpp"

namespace kartograf::pipeline {

namespace {

constexpr std::size_t kMinMatchedPoses = 3;

// Our rooms and classes at the centre of every plan cell (plan floor z = 0 in the world).
void resample_onto_plan(const MapPipelineResult& result, const OccupancyGrid& plan,
                        const Eigen::Isometry3d& world_from_map, MapEvaluation& out) {
  const Eigen::Isometry3d map_from_world = world_from_map.inverse();
  const semantic::SemanticGrid& grid = result.semantic;
  out.rooms_on_plan = LabelImage(plan.width(), plan.height(), 0);
  out.classes_on_plan = SemanticImage(plan.width(), plan.height(), SemanticClass::unknown);
  for (int row = 0; row < plan.height(); ++row) {
    for (int col = 0; col < plan.width(); ++col) {
      const Eigen::Vector2d world = plan.cell_center(col, row);
      const Eigen::Vector2d map =
          (map_from_world * Eigen::Vector3d(world.x(), world.y(), 0)).head<2>();
      const Eigen::Vector2i room_cell = result.occupancy.cell_of(map);
      if (result.occupancy.contains(room_cell))
        out.rooms_on_plan(col, row) = result.rooms.rooms(room_cell.x(), room_cell.y());
      const Eigen::Vector2i grid_cell = grid.cell_of(map);
      if (grid.contains(grid_cell) && !std::isnan(grid.weight(grid_cell.x(), grid_cell.y())))
        out.classes_on_plan(col, row) = grid.classes(grid_cell.x(), grid_cell.y());
    }
  }
}

// The inverse of the ATE's alignment takes the true positions into the map frame.
std::vector<FrameTrajectoryError> frame_errors(const eval::MatchedPoses& matched,
                                               const eval::AteResult& ate) {
  const eval::SimilarityTransform& a = ate.alignment;
  std::vector<FrameTrajectoryError> errors(matched.size());
  for (std::size_t k = 0; k < matched.size(); ++k) {
    const Eigen::Vector3d world = matched.ground_truth[k].pose.translation();
    errors[k].frame = static_cast<std::size_t>(matched.ground_truth[k].timestamp);
    errors[k].error_m = ate.errors_m[k];
    errors[k].true_position_in_map = a.rotation.transpose() * (world - a.translation) / a.scale;
  }
  return errors;
}

}  // namespace

MapEvaluation evaluate_map(const MapPipelineResult& result, const MapGroundTruth& truth) {
  MapEvaluation out;
  const eval::MatchedPoses matched = eval::match_frames(truth.poses, result.poses);
  if (matched.size() < kMinMatchedPoses) {
    out.skipped.push_back(
        "trajectory, rooms, classes: fewer than 3 frames have a ground-truth pose");
    return out;
  }
  out.trajectory = eval::evaluate_trajectory(matched, eval::Alignment::se3, eval::RpeParams{});
  out.frame_errors = frame_errors(matched, out.trajectory->ate);
  out.trajectory_at_measured_poses = eval::ate_at_measured_poses(matched);
  const eval::MatchedPoses odometry = eval::match_frames(truth.poses, result.slam.odometry.poses);
  if (odometry.size() >= kMinMatchedPoses) {
    out.odometry_trajectory =
        eval::evaluate_trajectory(odometry, eval::Alignment::se3, eval::RpeParams{});
    out.odometry_at_measured_poses = eval::ate_at_measured_poses(odometry);
  }
  if (!truth.plan) {
    out.skipped.push_back("rooms, classes: no floor plan");
    return out;
  }
  const OccupancyGrid& plan = *truth.plan;
  require(truth.rooms.width() == plan.width() && truth.rooms.height() == plan.height() &&
              truth.classes.width() == plan.width() && truth.classes.height() == plan.height(),
          "evaluate_map: the ground-truth rooms and classes must have the plan's size");
  const eval::SimilarityTransform& a = out.trajectory->ate.alignment;
  Eigen::Isometry3d world_from_map = Eigen::Isometry3d::Identity();
  world_from_map.linear() = a.rotation;
  world_from_map.translation() = a.translation;
  resample_onto_plan(result, plan, world_from_map, out);
  out.true_rooms = truth.rooms;
  out.true_classes = truth.classes;
  try {
    out.rooms = eval::evaluate_room_segmentation(truth.rooms, out.rooms_on_plan,
                                                 eval::room_evaluation_params(plan.resolution));
  } catch (const Error& e) {
    out.skipped.push_back(std::string("rooms: ") + e.what());
  }
  try {
    out.semantic = eval::evaluate_semantic_segmentation(truth.classes, out.classes_on_plan);
  } catch (const Error& e) {
    out.skipped.push_back(std::string("classes: ") + e.what());
  }
  return out;
}

}  // namespace kartograf::pipeline
