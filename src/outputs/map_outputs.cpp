#include "kartograf/outputs/map_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/formats/top_view.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/outputs/odometry_stats.hpp"
#include "kartograf/outputs/room_io.hpp"
#include "kartograf/outputs/semantic_map_io.hpp"
#include "outputs/json_array.hpp"
#include "outputs/map_report_html.hpp"

namespace kartograf::io {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using detail::json_array;

void write_text(const fs::path& path, const std::string& text) {
  detail::write_file_atomically(path, text.data(), text.size());
}

Json planes_json(const std::vector<mapping::MapPlane>& planes, const std::string& source) {
  Json list = Json::array();
  for (const mapping::MapPlane& p : planes) {
    list.push_back({{"id", p.id},
                    {"label", std::string(to_string(p.label))},
                    {"normal", json_array(p.normal)},
                    {"offset", p.offset},
                    {"centroid", json_array(p.centroid)},
                    {"major_axis", json_array(p.major_axis)},
                    {"minor_axis", json_array(p.minor_axis)},
                    {"extent_min", json_array(p.extent_min)},
                    {"extent_max", json_array(p.extent_max)},
                    {"area_m2", p.area},
                    {"points", p.point_count},
                    {"rms_error_m", p.rms_error},
                    {"views", p.views}});
  }
  return {{"format", "kartograf-map-planes"},
          {"version", 1},
          {"source", source},
          {"frame", "map: z up, floor at z = 0; n . p + offset = 0, n towards the viewer"},
          {"planes", std::move(list)}};
}

// ROS map_server's grey levels: free white, occupied black, unknown grey.
GrayImage occupancy_picture(const OccupancyGrid& grid) {
  GrayImage picture(grid.width(), grid.height());
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      const CellState c = grid.cells(x, y);
      picture(x, y) = c == CellState::free ? 254 : c == CellState::occupied ? 0 : 205;
    }
  }
  return picture;
}

Json optional_number(const std::optional<double>& value) {
  return value ? Json(*value) : Json();
}

Json trajectory_json(const eval::TrajectoryEvaluation& t) {
  return {{"ate_rmse_m", t.ate.translation_m.rmse},
          {"ate_max_m", t.ate.translation_m.max},
          {"rpe_translation_rmse_m", t.rpe.translation_m.rmse},
          {"rpe_rotation_rmse_deg", t.rpe.rotation_deg.rmse},
          {"poses", t.ate.translation_m.count}};
}

Json measured_poses_json(const eval::MeasuredPoseAte& m) {
  return {{"ate_rmse_m", m.ate.translation_m.rmse},
          {"poses", m.ate.translation_m.count},
          {"ground_truth_period", m.period}};
}

Json evaluation_json(const pipeline::MapEvaluation& e) {
  Json json = Json::object();
  if (e.trajectory) json["trajectory"] = trajectory_json(*e.trajectory);
  if (e.odometry_trajectory) json["odometry_trajectory"] = trajectory_json(*e.odometry_trajectory);
  if (e.trajectory_at_measured_poses)
    json["trajectory_at_measured_poses"] = measured_poses_json(*e.trajectory_at_measured_poses);
  if (e.odometry_at_measured_poses)
    json["odometry_at_measured_poses"] = measured_poses_json(*e.odometry_at_measured_poses);
  if (e.rooms) {
    const eval::RoomSegmentationScores& r = *e.rooms;
    json["rooms"] = {{"ground_truth_rooms", r.ground_truth_rooms},
                     {"segments", r.segments},
                     {"recall_mean", r.recall_mean},
                     {"recall_total", r.recall_total},
                     {"precision_mean", r.precision_mean},
                     {"precision_total", r.precision_total},
                     {"mcc", r.mcc},
                     {"room_recall", r.room_recall},
                     {"segment_precision", r.segment_precision}};
  }
  if (e.semantic) {
    Json iou = Json::object(), confusion = Json::object();
    for (int c = 0; c < kSemanticClassCount; ++c) {
      const std::string name(to_string(static_cast<SemanticClass>(c)));
      iou[name] = optional_number(e.semantic->iou[static_cast<std::size_t>(c)]);
      Json row = Json::object();  // cells of true class c, by our class
      for (int p = 0; p < kSemanticClassCount; ++p)
        row[std::string(to_string(static_cast<SemanticClass>(p)))] = e.semantic->confusion(c, p);
      confusion[name] = std::move(row);
    }
    json["classes"] = {{"iou", std::move(iou)},
                       {"confusion", std::move(confusion)},
                       {"mean_iou", e.semantic->mean_iou},
                       {"overall_accuracy", e.semantic->overall_accuracy},
                       {"cells", e.semantic->evaluated_pixels}};
  }
  json["not_scored"] = e.skipped;
  return json;
}

// What the loops and the tracking did, and where the trajectory is the motion model's: degenerate
// views whose free directions neither the images nor the features measured (a depth camera
// alone, a plain wall in the dark) and fallbacks.
Json slam_json(const pipeline::MapPipelineResult& r) {
  std::size_t accepted = 0, pruned = 0, by_appearance = 0;
  for (const mapping::LoopClosureRecord& l : r.slam.loop_closures) {
    accepted += l.closure.report.accepted();
    pruned += l.pruned;
    by_appearance += l.closure.report.accepted() && l.closure.candidate.by_appearance;
  }
  const OdometryFrameCounts counts = count_odometry_frames(r.slam.odometry.frames);
  const MotionPriorDifference& prior = counts.prior_difference;
  // Their poses (indices into the trajectory, from 0) too: where to distrust it. The first pose
  // is the origin, no step of the motion model's whatever its view.
  std::vector<std::size_t> unmeasured, fallbacks;
  for (const registration::OdometryFrame& f : r.slam.odometry.frames) {
    const bool measured = f.photometric || f.scanned || f.from_features || f.from_motion_prior;
    if (f.index > 0 && f.degenerate && !measured) unmeasured.push_back(f.index);
    if (f.fallback) fallbacks.push_back(f.index);
  }
  return {{"poses_given", r.slam.poses_given},
          {"loop_candidates", r.slam.loop_candidates},
          {"appearance_candidates", r.slam.appearance_candidates},
          {"loop_closures_accepted", accepted},
          {"loop_closures_by_appearance", by_appearance},
          {"frames_from_features", counts.from_features},
          {"frames_from_motion_prior", counts.motion_prior_frames},
          {"motion_prior_difference_median_m", prior.median_m},
          {"motion_prior_difference_max_m", prior.max_m},
          {"motion_prior_difference_max_deg", prior.max_deg},
          {"degenerate_frames", counts.degenerate_frames},
          {"degenerate_frames_unmeasured", unmeasured.size()},
          {"degenerate_unmeasured_poses", unmeasured},
          {"fallback_frames", counts.fallbacks},
          {"fallback_poses", fallbacks},
          {"loop_closures_pruned", pruned},
          {"pose_graph_converged", r.slam.final_graph.converged},
          {"map_points", r.map.size()}};
}

// The motion prior file's clock as measured, and the sentence the summary prints.
Json prior_clock_json(const PriorClock& clock) {
  const eval::ClockOffsetEstimate& m = clock.measured;
  return {{"offset_in_use_s", clock.given_s},
          {"measured_offset_s", m.observable ? Json(m.offset_s) : Json()},
          {"sigma_s", m.observable ? Json(m.sigma_s) : Json()},
          {"rms_deg", m.rms_deg},
          {"rms_deg_in_use", m.given_rms_deg},
          {"steps", m.steps},
          {"observable", m.observable},
          {"agrees", prior_clock_agrees(clock)},
          {"text", prior_clock_text(clock)}};
}

Json report_json(const pipeline::MapPipelineResult& r,
                 const std::optional<pipeline::MapEvaluation>& evaluation, const MapRunInfo& info) {
  Json json;
  json["format"] = "kartograf-map-report";
  json["version"] = 1;
  json["sequence"] = info.sequence;
  json["layout"] = info.layout;
  json["backend"] = info.backend;
  json["device"] = info.device;
  json["frames"] = r.poses.size();
  if (!info.input_json.empty()) json["input"] = Json::parse(info.input_json);
  Json stages = Json::array();
  for (const pipeline::StageTiming& t : r.timings)
    stages.push_back({{"stage", t.stage}, {"seconds", t.seconds}});
  // The odometry's compute time per frame (without file I/O): its speed target is per frame.
  const double odometry_ms = r.poses.empty() ? 0.0
                                             : 1000.0 * r.slam.odometry.compute_seconds /
                                                   static_cast<double>(r.poses.size());
  json["timing_s"] = {{"total", r.total_seconds()},
                      {"stages", std::move(stages)},
                      {"odometry_ms_per_frame", odometry_ms}};
  json["slam"] = slam_json(r);
  if (info.prior_clock) json["slam"]["motion_prior_clock"] = prior_clock_json(*info.prior_clock);
  const pipeline::VolumeStats& v = r.volume;
  json["volume"] = {{"blocks", v.blocks},
                    {"peak_blocks", v.peak_blocks},
                    {"budget_blocks", v.budget_blocks},
                    {"evictions", v.evictions},
                    {"refusions", v.refusions},
                    {"fused_frames", v.fused_frames},
                    {"fusion_s", v.fusion_seconds},
                    {"covers_all_frames", v.covers_all_frames},
                    {"frame_store_memory_bytes", v.store_memory_bytes},
                    {"frame_store_disk_bytes", v.store_disk_bytes},
                    {"keyframe_memory_bytes", v.keyframe_memory_bytes},
                    {"keyframe_disk_bytes", v.keyframe_disk_bytes},
                    {"mesh_vertices", r.mesh.vertices.size()},
                    {"mesh_triangles", r.mesh.triangles.size()}};
  json["views"] = {{"labelled", r.labelled_views},
                   {"unlabelled", r.unlabelled_views},
                   {"first_unlabelled_reason", r.first_unlabelled_reason}};
  std::map<std::string, int> plane_classes;
  for (const mapping::MapPlane& p : r.planes) ++plane_classes[std::string(to_string(p.label))];
  json["planes"] = {{"count", r.planes.size()}, {"by_class", plane_classes}};
  std::map<std::string, int> objects;
  for (const semantic::SemanticObject& o : r.semantic.objects)
    ++objects[std::string(semantic::to_string(o.kind))];
  json["grid"] = {{"width", r.semantic.width()},
                  {"height", r.semantic.height()},
                  {"resolution_m", r.semantic.resolution},
                  {"objects", objects}};
  json["rooms"] = {{"method", r.rooms.method},
                   {"count", r.rooms.records.size()},
                   {"enclosed_cells_taken", r.enclosed_cells_taken}};
  if (evaluation) json["evaluation"] = evaluation_json(*evaluation);
  if (!info.parameters_json.empty()) json["parameters"] = Json::parse(info.parameters_json);
  return json;
}

// Truth above ours: classes (the grid's colours) left, rooms right, on the plan's cells.
RgbImage evaluation_picture(const pipeline::MapEvaluation& e) {
  const int w = e.true_classes.width(), h = e.true_classes.height(), gap = 4;
  RgbImage picture(2 * w + gap, 2 * h + gap, Rgb8{255, 255, 255});
  const RgbImage rooms[] = {colorize_labels(e.true_rooms), colorize_labels(e.rooms_on_plan)};
  const SemanticImage* classes[] = {&e.true_classes, &e.classes_on_plan};
  for (int k = 0; k < 2; ++k) {
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const SemanticClass c = (*classes[k])(x, y);
        picture(x, y + k * (h + gap)) =
            c == SemanticClass::unknown ? semantic::kUnobservedColour : semantic::class_colour(c);
        picture(x + w + gap, y + k * (h + gap)) = rooms[k](x, y);
      }
    }
  }
  return picture;
}

// The true camera positions in the map frame, for the top view; empty without ground truth.
std::vector<Eigen::Vector3d> true_path(const std::optional<pipeline::MapEvaluation>& evaluation) {
  std::vector<Eigen::Vector3d> path;
  if (evaluation)
    for (const pipeline::FrameTrajectoryError& f : evaluation->frame_errors)
      path.push_back(f.true_position_in_map);
  return path;
}

}  // namespace

GrayImage esdf_picture(const Image<float>& esdf) {
  GrayImage grey(esdf.width(), esdf.height());
  for (std::size_t i = 0; i < esdf.pixels().size(); ++i) {
    const float metres = std::clamp(esdf.pixels()[i], 0.0f, 2.0f);
    grey.pixels()[i] = static_cast<std::uint8_t>(std::lround(metres / 2.0f * 255.0f));
  }
  return grey;
}

const std::vector<std::string>& map_output_files() {
  static const std::vector<std::string> files = {
      "trajectory.txt",     "map.ply",       "mesh.ply",      "planes.json",
      "occupancy.yaml",     "occupancy.pgm", "occupancy.png", "band_occupancy.yaml",
      "band_occupancy.pgm", "esdf.png",      "rooms.png",     "rooms_labels.png",
      "rooms.json",         "semantic.png",  "semantic.json", "top_view.png",
      "report.json",        "report.html"};
  return files;
}

void write_map_outputs(const fs::path& dir, const pipeline::MapPipelineResult& result,
                       const std::optional<pipeline::MapEvaluation>& evaluation,
                       const MapRunInfo& info) {
  // Everything that can fail on the data is rendered before the first file is written.
  Trajectory trajectory;
  const std::vector<double>& timestamps = result.slam.odometry.timestamps;
  for (std::size_t i = 0; i < result.poses.size(); ++i) {
    const double t =
        info.has_timestamps && i < timestamps.size() ? timestamps[i] : static_cast<double>(i);
    trajectory.push_back({t, result.poses[i]});
  }
  const std::string planes = planes_json(result.planes, info.sequence).dump(1) + "\n";
  const GrayImage occupancy = occupancy_picture(result.occupancy);
  const RgbImage rooms = room_overlay(result.occupancy, result.rooms.rooms);
  const RgbImage semantic = semantic::render_map(result.semantic).image;
  const RgbImage top_view = render_top_view(result.map, result.poses, {}, true_path(evaluation));
  const Json report = report_json(result, evaluation, info);
  const bool scored = evaluation && !evaluation->true_classes.empty();
  const std::string html = detail::map_report_html({report, result, evaluation, scored});
  const RgbImage scored_picture = scored ? evaluation_picture(*evaluation) : RgbImage();
  const GrayImage esdf = esdf_picture(result.esdf);

  fs::create_directories(dir);
  write_tum_trajectory(dir / "trajectory.txt", trajectory);
  write_ply(dir / "map.ply", result.map);
  write_mesh_ply(dir / "mesh.ply", result.mesh);
  if (result.band_occupancy.width() > 0) {
    write_ros_map(dir / "band_occupancy.yaml", result.band_occupancy);
    write_png(dir / "esdf.png", esdf);
  }
  write_text(dir / "planes.json", planes);
  write_ros_map(dir / "occupancy.yaml", result.occupancy);
  write_png(dir / "occupancy.png", occupancy);
  write_png(dir / "rooms.png", rooms);
  write_label_png(dir / "rooms_labels.png", result.rooms.rooms);
  write_rooms_json(dir / "rooms.json", result.rooms, result.occupancy, info.sequence);
  write_png(dir / "semantic.png", semantic);
  write_semantic_json(dir / "semantic.json", result.semantic, {}, info.sequence);
  write_png(dir / "top_view.png", top_view);
  if (scored) write_png(dir / "evaluation.png", scored_picture);
  write_text(dir / "report.json", report.dump(1) + "\n");
  write_text(dir / "report.html", html);
}

}  // namespace kartograf::io
