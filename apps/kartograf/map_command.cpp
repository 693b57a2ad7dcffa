// `kartograf map SEQUENCE --out DIR`: the whole pipeline (pipeline/map_pipeline.hpp) on an RGB-D
// sequence, scored against the sequence's ground truth where it has one (poses; a synthetic
// building's floor plan), written by io/map_outputs.hpp. Progress per stage on stderr, the report's
// path on stdout. Wiring only.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/outputs/map_outputs.hpp"
#include "kartograf/outputs/map_run_info.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"
#include "kartograf/pipeline/map_evaluation.hpp"
#include "kartograf/pipeline/mapper.hpp"
#include "option_checks.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

namespace {

void print_summary(std::ostream& out, const pipeline::MapPipelineResult& r,
                   const std::optional<pipeline::MapEvaluation>& e) {
  char line[256];
  std::snprintf(line, sizeof(line),
                "  %zu frames, %d views labelled, %zu planes, %zu objects on a %dx%d grid, %zu "
                "rooms (%s)\n",
                r.poses.size(), r.labelled_views, r.planes.size(), r.semantic.objects.size(),
                r.semantic.width(), r.semantic.height(), r.rooms.records.size(),
                r.rooms.method.c_str());
  out << line << model_tracking_line(r.slam.odometry) << "  seconds";
  for (const pipeline::StageTiming& t : r.timings) {
    std::snprintf(line, sizeof(line), " %s %.1f,", t.stage.c_str(), t.seconds);
    out << line;
  }
  std::snprintf(line, sizeof(line), " total %.1f\n", r.total_seconds());
  out << line;
  if (!e) return;
  if (e->trajectory) {
    std::snprintf(line, sizeof(line), "  ate_rmse_m %.4f  rpe_rmse_m %.4f\n",
                  e->trajectory->ate.translation_m.rmse, e->trajectory->rpe.translation_m.rmse);
    out << line;
  }
  if (e->trajectory_at_measured_poses) out << measured_poses_line(*e->trajectory_at_measured_poses);
  if (e->rooms) {
    std::snprintf(line, sizeof(line), "  rooms recall %.3f precision %.3f mcc %.3f\n",
                  e->rooms->recall_mean, e->rooms->precision_mean, e->rooms->mcc);
    out << line;
  }
  if (e->semantic) {
    out << "  iou";
    for (int c = 1; c < kSemanticClassCount; ++c) {
      const auto& iou = e->semantic->iou[static_cast<std::size_t>(c)];
      if (!iou) continue;
      std::snprintf(line, sizeof(line), " %s %.3f",
                    std::string(to_string(SemanticClass(c))).c_str(), *iou);
      out << line;
    }
    out << "\n";
  }
}

}  // namespace

CLI::App* add_map_command(CLI::App& app, MapOptions& o) {
  CLI::App* command = app.add_subcommand(
      "map",
      "The whole pipeline on an RGB-D sequence: SLAM, planes, occupancy grid, rooms, semantic "
      "grid, and a report (with every metric its ground truth allows)");
  add_sequence_run_options(*command, o.run);
  command->add_option("--out", o.out_dir, "Output folder (created if missing)")->required();
  command->add_option("--label-step", o.label_step, "Label and extract planes in every k-th frame")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  command
      ->add_option("--max-views", o.max_views,
                   "Label at most this many frames, spread evenly (bounds the views' memory)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  command
      ->add_option("--label-width", o.label_width, "Labelled views: at most this many pixels wide")
      ->check(CLI::Range(64, 4096))
      ->capture_default_str();
  command->add_option("--resolution", o.resolution, "Grid cell size [m]")
      ->check(finite_in(0.01, 1.0))
      ->capture_default_str();
  command->add_option("--rooms", o.room_method, "Room segmentation method")
      ->check(CLI::IsMember({"morphological", "distance", "voronoi", "feature", "vrf"}))
      ->capture_default_str();
  command->add_flag("--no-features", o.no_features,
                    "No local image features: loop closure by pose only, no odometry recovery "
                    "from features");
  command->add_option("--poses", o.poses,
                      "Known camera poses instead of SLAM: 'groundtruth' (the sequence's own) or "
                      "a TUM trajectory file (at each frame's timestamp, interpolated between two "
                      "poses at most 0.5 s apart, else the nearest within 20 ms)");
  command->add_option("--voxel", o.voxel, "TSDF voxel size [m] (truncation: 3 voxels)")
      ->check(finite_in(0.005, 0.2))
      ->capture_default_str();
  command
      ->add_option("--max-blocks", o.max_blocks,
                   "TSDF budget in blocks of 8^3 voxels (6 KiB each); past 85 %, blocks far from "
                   "the camera are evicted")
      ->check(CLI::Range(std::size_t{64}, std::size_t{1} << 23))
      ->capture_default_str();
  command->add_flag("--force", o.force, "Overwrite the files of an earlier run");
  return command;
}

int run_map_command(const MapOptions& o, std::ostream& out, std::ostream& err) {
  std::vector<std::string> known_files = io::map_output_files();
  known_files.push_back("evaluation.png");
  OutputFolder folder("map", o.out_dir, o.force, known_files);
  OpenedRun run = open_run(o.run, err, o.poses);
  // A depth camera alone: the features (ORB) have no image to work on; the views' planes and
  // labels come from the depth (docs/user-guide.md, "A depth camera alone").
  const bool wants_features = !o.no_features && o.poses.empty();
  if (wants_features && !run.opened.has_color)
    err << "map: no colour images: no local image features (as --no-features)\n";
  const compute::Context context = make_run_context(o.run);
  calibrate_prior_clock(o.run, context, run, err);
  pipeline::MapperParams params;
  pipeline::MapPipelineParams& stages = params.pipeline;
  stages.slam.odometry = odometry_params(o.run);
  stages.slam.model = model_tracking_params(o.run);
  stages.label_step = o.label_step;
  stages.max_views = o.max_views;
  stages.features = wants_features && run.opened.has_color;
  stages.known_poses = known_pose_lookup("map", o.poses, !run.opened.detected.has_timestamps,
                                         "--poses", run.pose_mount);
  stages.label_width = o.label_width;
  stages.grid.resolution = o.resolution;
  warn_untuned_grid_resolution("map", o.resolution, err);
  stages.room_method = rooms::parse_room_method(o.room_method);
  params.volume.voxel_size = o.voxel;
  params.volume.truncation = 3 * o.voxel;
  params.volume.max_blocks = o.max_blocks;

  ProgressBar bar(err, o.run.progress);
  pipeline::MapPipelineObserver observer;
  observer.slam = slam_progress_observer(err, bar);
  int stage_number = 0;
  observer.on_stage = [&](std::string_view stage) {
    bar.finish();
    if (o.run.progress) err << "map: stage " << ++stage_number << "/6: " << stage << "\n";
  };
  const pipeline::MapPipelineResult result =
      pipeline::run_map_pipeline(context, *run.source, params, observer);
  bar.finish();
  if (result.unlabelled_views > 0)
    err << "map: " << result.unlabelled_views << " of "
        << result.labelled_views + result.unlabelled_views << " views could not be labelled, e.g. "
        << result.first_unlabelled_reason << "\n";

  pipeline::MapGroundTruth truth;
  truth.poses = run.source->ground_truth();
  if (const auto plan = io::read_floor_plan_truth(o.run.sequence)) {
    truth.plan = plan->plan;
    truth.rooms = plan->rooms;
    truth.classes = plan->classes;
  }
  std::optional<pipeline::MapEvaluation> evaluation;
  if (!truth.poses.empty()) evaluation = pipeline::evaluate_map(result, truth);

  io::MapRunInfo info = io::map_run_info(run_record(o.run, context), run.opened, params);
  info.prior_clock =
      measure_prior_clock(run, result.slam.odometry.poses, result.slam.odometry.timestamps);
  {
    const InterruptsDeferred writing;  // a signal waits for the files, then drops them
    io::write_map_outputs(folder.dir(), result, evaluation, info);
  }
  folder.commit();
  out << "map: " << info.sequence << " (" << info.layout << "), backend " << info.backend << " ("
      << info.device << ")\n";
  out << "  " << io::describe_input(run.opened) << "\n";
  print_summary(out, result, evaluation);
  out << prior_clock_line(info.prior_clock);
  out << "  report: " << (o.out_dir / "report.html").string() << "\n";
  return 0;
}

}  // namespace kartograf::cli
