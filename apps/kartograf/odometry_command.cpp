// `kartograf odometry SEQUENCE --out traj.txt`: RGB-D odometry over a sequence folder
// (mapping::run_odometry), the trajectory in TUM format, a summary with throughput and, when the
// sequence has ground truth, the ATE. Wiring only.
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>

#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/formats/text_file.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/outputs/odometry_stats.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

CLI::App* add_odometry_command(CLI::App& app, OdometryOptions& o) {
  CLI::App* command = app.add_subcommand(
      "odometry", "Frame-to-frame RGB-D odometry over a sequence folder; writes a TUM trajectory");
  add_sequence_run_options(*command, o.run);
  command->add_option("--out", o.out, "Trajectory file (TUM: timestamp tx ty tz qx qy qz qw)")
      ->required();
  command->add_option("--stats", o.stats, "Also write per-frame statistics (JSON)");
  command->add_flag("--force", o.force, "Replace the files of an earlier run");
  return command;
}

int run_odometry_command(const OdometryOptions& o, std::ostream& out, std::ostream& err) {
  OutputFiles files("odometry", o.force);
  const std::filesystem::path trajectory_file = files.add("--out", o.out);
  const std::filesystem::path stats_file =
      o.stats.empty() ? o.stats : files.add("--stats", o.stats);
  OpenedRun run = open_run(o.run, err);
  const compute::Context context = make_run_context(o.run);
  calibrate_prior_clock(o.run, context, run, err);
  const registration::OdometryParams params = odometry_params(o.run);
  const bool has_timestamps = run.opened.detected.has_timestamps;

  ProgressBar bar(err, o.run.progress);
  const mapping::SlamObserver observer = slam_progress_observer(err, bar);
  const mapping::OdometryRun result =
      mapping::run_odometry(context, *run.source, params, observer, model_tracking_params(o.run));
  bar.finish();

  const InterruptsDeferred writing;  // a signal waits for the files, then drops them
  io::write_tum_trajectory(trajectory_file,
                           stamped_trajectory(result.poses, result.timestamps, has_timestamps));
  const auto ate = absolute_trajectory_error(*run.source, result.poses);
  const double frames = static_cast<double>(result.poses.size());
  const io::OdometryThroughput throughput = io::odometry_throughput(result);
  const io::SequenceRunRecord record = run_record(o.run, context);

  out << "odometry: " << o.run.sequence.string() << " ("
      << io::to_string(run.opened.detected.layout) << ", " << result.poses.size()
      << " frames), method " << o.run.method << ", backend " << record.backend << " ("
      << record.device << ")\n"
      << "  " << io::describe_input(run.opened) << "\n"
      << "  trajectory " << o.out.string() << "\n";
  char line[256];
  std::snprintf(line, sizeof(line),
                "  frames_per_s %.1f with file I/O, %.1f without (loading %.1f ms/frame on the "
                "prefetch thread)\n",
                throughput.with_io, throughput.without_io,
                1000.0 * result.timing.load_seconds / std::max(frames, 1.0));
  out << line;
  out << "  " << io::frame_counts_line(io::count_odometry_frames(result.frames)) << "\n";
  out << prior_clock_line(measure_prior_clock(run, result.poses, result.timestamps));
  out << model_tracking_line(result);
  if (ate) {
    std::snprintf(line, sizeof(line), "  ate_rmse_m %.6f (max %.6f, %zu poses with ground truth)\n",
                  ate->translation_m.rmse, ate->translation_m.max, ate->translation_m.count);
    out << line;
  }
  if (const auto measured = ate_at_measured_poses(*run.source, result.poses))
    out << measured_poses_line(*measured);

  if (!o.stats.empty()) {
    io::write_text_file(stats_file,
                        io::odometry_stats_json(record, run.opened, params, result, ate));
  }
  files.commit();
  return 0;
}

}  // namespace kartograf::cli
