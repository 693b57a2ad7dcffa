// `kartograf slam SEQUENCE --out DIR`: odometry, loop closure, pose graph and fused map
// (mapping::run_slam) over a sequence folder. Writes DIR/trajectory.txt (TUM; the frame number is
// the timestamp where the sequence has none), odometry.txt (before the pose graph), map.ply,
// top_view.png, stats.json and, when the sequence has ground truth, groundtruth.txt stamped the
// same way (for `kartograf eval traj`). Wiring only.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/features/orb_front_end.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/formats/text_file.hpp"
#include "kartograf/formats/top_view.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/outputs/slam_stats.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"
#include "option_checks.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

namespace {

// What the summary and stats.json say beyond the result itself.
struct SlamFigures {
  io::SlamAccuracy accuracy;
  io::LoopClosureCounts loops;
};

SlamFigures slam_figures(const OpenedRun& run, const mapping::SlamResult& result) {
  SlamFigures f;
  f.accuracy.slam = absolute_trajectory_error(*run.source, result.poses);
  f.accuracy.odometry = absolute_trajectory_error(*run.source, result.odometry.poses);
  f.accuracy.slam_at_measured = ate_at_measured_poses(*run.source, result.poses);
  f.accuracy.odometry_at_measured = ate_at_measured_poses(*run.source, result.odometry.poses);
  f.loops = io::count_loop_closures(result);
  return f;
}

// Where the ground truth interpolates between measured poses, the ATEs at those alone.
void print_measured_pose_line(std::ostream& out, const io::SlamAccuracy& a) {
  if (!a.slam_at_measured || !a.odometry_at_measured) return;
  char line[256];
  std::snprintf(line, sizeof(line),
                "  ground truth measured every %zu frames, interpolated between: at its %zu "
                "measured poses odometry_ate_rmse_m %.6f slam_ate_rmse_m %.6f\n",
                a.slam_at_measured->period, a.slam_at_measured->ate.translation_m.count,
                a.odometry_at_measured->ate.translation_m.rmse,
                a.slam_at_measured->ate.translation_m.rmse);
  out << line;
}

// Writes the files into the staging folder; returns whether groundtruth.txt was among them.
bool write_slam_files(const std::filesystem::path& dir, const OpenedRun& run,
                      const mapping::SlamResult& result, bool build_map, const std::string& stats) {
  const bool has_timestamps = run.opened.detected.has_timestamps;
  const std::vector<double>& timestamps = result.odometry.timestamps;
  io::write_tum_trajectory(dir / "trajectory.txt",
                           stamped_trajectory(result.poses, timestamps, has_timestamps));
  io::write_tum_trajectory(dir / "odometry.txt",
                           stamped_trajectory(result.odometry.poses, timestamps, has_timestamps));
  const Trajectory truth = ground_truth_trajectory(*run.source, timestamps, has_timestamps);
  if (!truth.empty()) io::write_tum_trajectory(dir / "groundtruth.txt", truth);
  if (build_map) io::write_ply(dir / "map.ply", result.map);
  io::write_top_view_png(dir / "top_view.png", result.map, result.poses);
  io::write_text_file(dir / "stats.json", stats);
  return !truth.empty();
}

void print_slam_summary(std::ostream& out, const SlamOptions& o, const OpenedRun& run,
                        const io::SequenceRunRecord& record, const mapping::SlamResult& result,
                        const SlamFigures& f, bool wrote_truth) {
  const mapping::SlamTimings& t = result.timing;
  const double frames = static_cast<double>(result.poses.size());
  char line[256];
  out << "slam: " << o.run.sequence.string() << " (" << io::to_string(run.opened.detected.layout)
      << ", " << result.poses.size() << " frames), method " << o.run.method << ", backend "
      << record.backend << " (" << record.device << ")\n";
  out << "  " << io::describe_input(run.opened) << "\n";
  out << "  " << io::frame_counts_line(io::count_odometry_frames(result.odometry.frames)) << "\n";
  out << prior_clock_line(
      measure_prior_clock(run, result.odometry.poses, result.odometry.timestamps));
  out << model_tracking_line(result.odometry);
  std::snprintf(line, sizeof(line),
                "  loop_closures %zu accepted of %zu candidates, %zu pruned by the pose graph\n",
                f.loops.accepted, result.loop_candidates, f.loops.pruned);
  out << line;
  std::snprintf(line, sizeof(line), "  map_points %zu (voxel %.3f m)\n", result.map.size(),
                o.voxel_size);
  out << line;
  if (f.accuracy.odometry && f.accuracy.slam) {
    std::snprintf(line, sizeof(line), "  odometry_ate_rmse_m %.6f\n  slam_ate_rmse_m %.6f\n",
                  f.accuracy.odometry->translation_m.rmse, f.accuracy.slam->translation_m.rmse);
    out << line;
    print_measured_pose_line(out, f.accuracy);
  }
  std::snprintf(line, sizeof(line),
                "  seconds %.2f total: odometry %.2f, loop closure %.2f, pose graph %.2f, map "
                "%.2f, file loading %.2f (prefetched); %.1f frames/s overall\n",
                t.total_seconds, t.odometry_seconds, t.loop_closure_seconds, t.optimisation_seconds,
                t.map_seconds, t.load_seconds,
                t.total_seconds > 0 ? frames / t.total_seconds : 0.0);
  out << line << "  wrote " << o.out_dir.string() << "/{trajectory.txt, odometry.txt, "
      << (o.no_map ? "" : "map.ply, ") << "top_view.png, stats.json"
      << (wrote_truth ? ", groundtruth.txt" : "") << "}\n";
}

}  // namespace

CLI::App* add_slam_command(CLI::App& app, SlamOptions& o) {
  CLI::App* command = app.add_subcommand(
      "slam", "RGB-D SLAM: odometry, loop closure, pose graph and a fused map of a sequence");
  add_sequence_run_options(*command, o.run);
  command->add_option("--out", o.out_dir, "Output folder (created if missing)")->required();
  command->add_flag("--no-loop-closure", o.no_loop_closure,
                    "Optimise odometry edges only (frame-to-frame and anchor re-estimates)");
  command->add_flag("--no-map", o.no_map, "Skip the map (no second pass over the frames)");
  command->add_flag("--features", o.features,
                    "ORB features (as kartograf map): loop-closure candidates by appearance too, "
                    "and the odometry seeded by features after large or rejected steps");
  command->add_option("--voxel", o.voxel_size, "Map voxel size [m]")
      ->check(finite_in(0.001, 10.0))
      ->capture_default_str();
  command->add_flag("--force", o.force, "Replace the folder of an earlier run as a whole");
  return command;
}

int run_slam_command(const SlamOptions& o, std::ostream& out, std::ostream& err) {
  OutputFolder folder("slam", o.out_dir, o.force,
                      {"trajectory.txt", "odometry.txt", "groundtruth.txt", "map.ply",
                       "top_view.png", "stats.json"});
  OpenedRun run = open_run(o.run, err);
  const compute::Context context = make_run_context(o.run);
  calibrate_prior_clock(o.run, context, run, err);
  mapping::SlamParams params;
  params.odometry = odometry_params(o.run);
  params.loop_closure = !o.no_loop_closure;
  params.build_map = !o.no_map;
  params.map.voxel_size = o.voxel_size;
  params.model = model_tracking_params(o.run);
  if (o.features) {
    require_colour(run.opened, o.run.sequence, "--features (ORB on the colour images)");
    params.features = std::make_shared<const features::OrbFrontEnd>(pipeline::map_orb_params());
    params.odometry.features = params.features;
  }

  ProgressBar bar(err, o.run.progress);
  const mapping::SlamObserver observer = slam_progress_observer(err, bar);
  const mapping::SlamResult result = mapping::run_slam(context, *run.source, params, observer);
  bar.finish();

  const SlamFigures figures = slam_figures(run, result);
  const io::SequenceRunRecord record = run_record(o.run, context);
  const std::string stats =
      io::slam_stats_json(record, run.opened, params, result, figures.accuracy);
  bool wrote_truth = false;
  {
    const InterruptsDeferred writing;  // a signal waits for the files, then drops them
    wrote_truth = write_slam_files(folder.dir(), run, result, params.build_map, stats);
    folder.commit();
  }
  print_slam_summary(out, o, run, record, result, figures, wrote_truth);
  return 0;
}

}  // namespace kartograf::cli
