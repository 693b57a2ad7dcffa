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
  const OpenedRun run = open_run(o.run, err);
  const compute::Context context = make_run_context(o.run);
  const registration::OdometryParams params = odometry_params(o.run);
  const bool has_timestamps = run.opened.detected.has_timestamps;

  ProgressBar bar(err, o.run.progress);
  const mapping::SlamObserver observer = slam_progress_observer(err, bar);
  const mapping::OdometryRun result = mapping::run_odometry(context, *run.source, params, observer);
  bar.finish();

  const InterruptsDeferred writing;  // a signal waits for the files, then drops them
  io::write_tum_trajectory(trajectory_file,
                           stamped_trajectory(result.poses, result.timestamps, has_timestamps));
  const auto ate = absolute_trajectory_error(*run.source, result.poses);
  const double frames = static_cast<double>(result.poses.size());
  const double with_io = result.timing.wall_seconds > 0 ? frames / result.timing.wall_seconds : 0;
  const double without_io = result.compute_seconds > 0 ? frames / result.compute_seconds : 0;
  const Json summary = frame_summary_json(result.frames);

  out << "odometry: " << o.run.sequence.string() << " ("
      << io::to_string(run.opened.detected.layout) << ", " << result.poses.size()
      << " frames), method " << o.run.method << ", backend "
      << compute::to_string(context.backend()) << " (" << context.device_info().name << ")\n"
      << "  " << io::describe_input(run.opened) << "\n"
      << "  trajectory " << o.out.string() << "\n";
  char line[256];
  std::snprintf(line, sizeof(line),
                "  frames_per_s %.1f with file I/O, %.1f without (loading %.1f ms/frame on the "
                "prefetch thread)\n",
                with_io, without_io, 1000.0 * result.timing.load_seconds / std::max(frames, 1.0));
  out << line;
  out << "  " << frame_summary_line(summary) << "\n";
  if (ate) {
    std::snprintf(line, sizeof(line), "  ate_rmse_m %.6f (max %.6f, %zu poses with ground truth)\n",
                  ate->translation_m.rmse, ate->translation_m.max, ate->translation_m.count);
    out << line;
  }

  if (!o.stats.empty()) {
    Json json;
    json["sequence"] = o.run.sequence.string();
    json["layout"] = io::to_string(run.opened.detected.layout);
    json["input"] = input_json(run.opened);
    json["method"] = o.run.method;
    json["backend"] = compute::to_string(context.backend());
    json["device"] = context.device_info().name;
    json["reestimate_interval"] = params.reestimate_interval;
    json["frames_per_s_with_io"] = with_io;
    json["frames_per_s_without_io"] = without_io;
    json["wall_seconds"] = result.timing.wall_seconds;
    json["load_seconds"] = result.timing.load_seconds;
    json["ate_rmse_m"] = ate ? Json(ate->translation_m.rmse) : Json();
    json["summary"] = summary;
    Json per_frame = Json::array();
    for (const auto& f : result.frames) per_frame.push_back(frame_json(f));
    json["per_frame"] = std::move(per_frame);
    io::write_text_file(stats_file, json.dump(1) + "\n");
  }
  files.commit();
  return 0;
}

}  // namespace kartograf::cli
