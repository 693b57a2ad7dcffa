#include "kartograf/outputs/slam_stats.hpp"

#include <utility>

#include <Eigen/Geometry>

#include "run_json.hpp"

namespace kartograf::io {

namespace {

using detail::RunJson;

RunJson loop_closure_json(const mapping::LoopClosureRecord& record) {
  const mapping::LoopCandidate& c = record.closure.candidate;
  RunJson json;
  json["query_frame"] = c.query_frame;
  json["match_frame"] = c.match_frame;
  json["distance_m"] = c.distance_m;
  json["view_angle_deg"] = c.view_angle_deg;
  json["overlap"] = c.overlap;
  json["by_appearance"] = c.by_appearance;
  if (c.by_appearance) {
    json["feature_inliers"] = c.feature_inliers;
    json["appearance_score"] = c.appearance_score;
  }
  json["registration"] = detail::registration_report_json(record.closure.report);
  json["feature_confirmation"] = mapping::to_string(record.closure.confirmation);
  if (record.closure.correction_chi2 >= 0) json["correction_chi2"] = record.closure.correction_chi2;
  const Eigen::Isometry3d& motion = record.closure.constraint.motion;
  const Eigen::Quaterniond rotation(motion.linear());
  json["motion"] = {motion.translation().x(),
                    motion.translation().y(),
                    motion.translation().z(),
                    rotation.x(),
                    rotation.y(),
                    rotation.z(),
                    rotation.w()};
  // Directions the loop left to the estimate (weak in the query's geometry): not measured.
  json["free_directions"] = record.closure.free_directions;
  json["chi2"] = record.chi2;
  json["residual_m"] = record.residual_m;
  json["residual_deg"] = record.residual_deg;
  json["pruned"] = record.pruned;
  return json;
}

RunJson loop_closures_json(const mapping::SlamParams& params, const mapping::SlamResult& result) {
  const LoopClosureCounts counts = count_loop_closures(result);
  RunJson closures = RunJson::array();
  for (const mapping::LoopClosureRecord& record : result.loop_closures)
    closures.push_back(loop_closure_json(record));
  return {{"enabled", params.loop_closure},
          {"candidates", result.loop_candidates},
          {"appearance_candidates", result.appearance_candidates},
          {"accepted", counts.accepted},
          {"pruned", counts.pruned},
          {"closures", std::move(closures)}};
}

RunJson ate_rmse_json(const std::optional<eval::AteResult>& ate) {
  return ate ? RunJson(ate->translation_m.rmse) : RunJson();
}

// Where the ground truth interpolates between measured poses: the ATEs at those alone.
RunJson measured_poses_json(const eval::MeasuredPoseAte& slam,
                            const eval::MeasuredPoseAte& odometry) {
  return {{"ground_truth_period", slam.period},
          {"poses", slam.ate.translation_m.count},
          {"odometry_ate_rmse_m", odometry.ate.translation_m.rmse},
          {"slam_ate_rmse_m", slam.ate.translation_m.rmse}};
}

// Frame-to-frame, or frame-to-model with what the model did.
RunJson tracking_json(const mapping::SlamParams& params, const mapping::OdometryRun& run) {
  if (!run.model_tracking) return {{"kind", "frame"}};
  return {{"kind", "model"},
          {"voxel_size_m", params.model.volume.voxel_size},
          {"model_kept", run.model_kept},
          {"model_evictions", run.model_evictions},
          {"model_seconds", run.model_seconds}};
}

}  // namespace

LoopClosureCounts count_loop_closures(const mapping::SlamResult& result) {
  LoopClosureCounts counts;
  for (const mapping::LoopClosureRecord& record : result.loop_closures) {
    counts.accepted += record.closure.report.accepted();
    counts.pruned += record.pruned;
  }
  return counts;
}

std::string slam_stats_json(const SequenceRunRecord& record, const OpenedSequence& opened,
                            const mapping::SlamParams& params, const mapping::SlamResult& result,
                            const SlamAccuracy& accuracy) {
  const mapping::SlamTimings& t = result.timing;
  RunJson json;
  json["sequence"] = record.sequence;
  json["layout"] = to_string(opened.detected.layout);
  json["input"] = detail::input_json(opened);
  json["frames"] = result.poses.size();
  json["method"] = record.method;
  json["backend"] = record.backend;
  json["device"] = record.device;
  json["reestimate_interval"] = params.odometry.reestimate_interval;
  json["tracking"] = tracking_json(params, result.odometry);
  json["odometry_ate_rmse_m"] = ate_rmse_json(accuracy.odometry);
  json["slam_ate_rmse_m"] = ate_rmse_json(accuracy.slam);
  if (accuracy.slam_at_measured && accuracy.odometry_at_measured) {
    json["at_measured_poses"] =
        measured_poses_json(*accuracy.slam_at_measured, *accuracy.odometry_at_measured);
  }
  json["timing_s"] = {{"total", t.total_seconds},
                      {"odometry", t.odometry_seconds},
                      {"loop_closure", t.loop_closure_seconds},
                      {"optimisation", t.optimisation_seconds},
                      {"map", t.map_seconds},
                      {"loading", t.load_seconds}};
  json["loop_closure"] = loop_closures_json(params, result);
  json["pose_graph"] = {{"nodes", result.poses.size()},
                        {"edges", result.graph_edges},
                        {"optimisations", result.graph_optimisations},
                        {"iterations", result.final_graph.iterations},
                        {"initial_cost", result.final_graph.initial_cost},
                        {"final_cost", result.final_graph.final_cost},
                        {"converged", result.final_graph.converged}};
  json["map"] = {{"points", result.map.size()},
                 {"voxels", result.map_voxels},
                 {"voxel_size_m", params.map.voxel_size}};
  json["odometry"] = detail::frame_counts_json(result.odometry.frames);
  json["per_frame"] = detail::per_frame_json(result.odometry.frames);
  return json.dump(1) + "\n";
}

}  // namespace kartograf::io
