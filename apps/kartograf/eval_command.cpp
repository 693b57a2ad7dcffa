// `kartograf eval traj|planes|rooms|semantic`: reads the files, calls kartograf::eval, prints a
// table (or one JSON object with --json; kartograf/outputs/eval_report.hpp). No metric is computed
// here.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/eval/clock_offset.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/outputs/eval_report.hpp"
#include "option_checks.hpp"

namespace kartograf::cli {

namespace {

std::vector<double> timestamps(const Trajectory& trajectory) {
  std::vector<double> times;
  times.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) times.push_back(pose.timestamp);
  return times;
}

Trajectory sorted_by_time(Trajectory trajectory) {
  sort_by_time(trajectory);
  return trajectory;
}

// --offset: the number given, or measured from the turning rates ("auto"; an Error where they
// cannot tell it).
io::TimeOffset time_offset(const EvalOptions& options, const Trajectory& ground_truth,
                           const Trajectory& estimate) {
  if (options.offset != "auto") return {std::stod(options.offset), std::nullopt};
  const eval::ClockOffsetEstimate measured =
      eval::estimate_clock_offset(sorted_by_time(estimate), sorted_by_time(ground_truth));
  require(measured.observable,
          "--offset auto: the clock offset is not measurable from '" +
              options.ground_truth.string() + "' and '" + options.prediction.string() + "' (" +
              std::to_string(measured.steps) +
              " steps compared within +-0.5 s of the other's times; they must turn, and not at "
              "one rate): give --offset S");
  return {measured.offset_s, measured};
}

io::MetricReport trajectory_report(const EvalOptions& options) {
  const Trajectory ground_truth = io::read_tum_trajectory(options.ground_truth);
  Trajectory estimate = io::read_tum_trajectory(options.prediction);
  const io::TimeOffset offset = time_offset(options, ground_truth, estimate);
  for (StampedPose& pose : estimate) pose.timestamp += offset.seconds;
  const auto pairs = io::associate_timestamps(timestamps(ground_truth), timestamps(estimate),
                                              options.max_difference);
  require(!pairs.empty(), "no estimated pose has a ground-truth pose within --max-difference " +
                              std::to_string(options.max_difference) +
                              " s; do both files use the same clock?");
  const eval::MatchedPoses matched = eval::match_poses(ground_truth, estimate, pairs);
  const eval::Alignment alignment = options.sim3 ? eval::Alignment::sim3 : eval::Alignment::se3;
  const bool seconds = options.delta_unit == "seconds";
  const eval::TrajectoryEvaluation result = eval::evaluate_trajectory(
      matched, alignment,
      {options.delta, seconds ? eval::DeltaUnit::seconds : eval::DeltaUnit::frames});
  io::TrajectoryReportInput input;
  input.ground_truth_file = options.ground_truth.string();
  input.estimate_file = options.prediction.string();
  input.ground_truth_poses = ground_truth.size();
  input.estimate_poses = estimate.size();
  input.matched_poses = matched.size();
  input.max_difference_s = options.max_difference;
  input.offset = offset;
  input.sim3 = options.sim3;
  input.delta = options.delta;
  input.delta_unit = options.delta_unit;
  io::MetricReport report = io::trajectory_report(result, input);
  if (options.worst_steps > 0) {
    io::add_worst_steps(report, eval::worst_steps(matched, options.worst_steps, alignment));
  }
  return report;
}

io::MetricReport plane_report(const EvalOptions& options) {
  const LabelImage ground_truth = io::read_label_png(options.ground_truth);
  const LabelImage predicted = io::read_label_png(options.prediction);
  const eval::SegCompResult result =
      eval::compare_plane_segmentations(ground_truth, predicted, {options.threshold});
  return io::plane_report(result, options.ground_truth.string(), options.prediction.string(),
                          options.threshold);
}

io::MetricReport room_report(const EvalOptions& options) {
  const LabelImage ground_truth = io::read_ground_truth_rooms(options.ground_truth);
  const LabelImage segmentation = io::read_ground_truth_rooms(options.prediction);
  return io::room_report(
      eval::evaluate_room_segmentation(ground_truth, segmentation,
                                       eval::room_evaluation_params(options.resolution)),
      options.ground_truth.string(), options.prediction.string());
}

io::MetricReport semantic_report(const EvalOptions& options) {
  const SemanticImage ground_truth = io::read_semantic_png(options.ground_truth);
  const SemanticImage predicted = io::read_semantic_png(options.prediction);
  return io::semantic_report(eval::evaluate_semantic_segmentation(ground_truth, predicted),
                             options.ground_truth.string(), options.prediction.string());
}

}  // namespace

CLI::App* add_eval_command(CLI::App& app, EvalOptions& options) {
  CLI::App* eval = app.add_subcommand("eval",
                                      "Score trajectories, planes, rooms or semantics "
                                      "against ground truth");
  eval->require_subcommand(1);
  const auto add_metric = [&](const char* name, const char* description, const char* gt_help,
                              const char* prediction_help) {
    CLI::App* metric = eval->add_subcommand(name, description);
    metric->add_option("GT", options.ground_truth, gt_help)->required();
    metric->add_option("PREDICTION", options.prediction, prediction_help)->required();
    metric->add_flag("--json", options.json, "Print one JSON object instead of a table");
    metric->callback([&options, name] { options.metric = name; });
    return metric;
  };

  CLI::App* traj = add_metric("traj", "ATE and RPE of a trajectory (TUM format)",
                              "Ground-truth trajectory (timestamp tx ty tz qx qy qz qw)",
                              "Estimated trajectory, same format");
  traj->add_option("--delta", options.delta, "RPE step")
      ->check(finite_positive())
      ->capture_default_str();
  traj->add_option("--delta-unit", options.delta_unit, "Unit of --delta")
      ->check(CLI::IsMember({"frames", "seconds"}))
      ->capture_default_str();
  traj->add_flag("--sim3", options.sim3, "Align with a scale too (monocular estimates)");
  traj->add_option("--worst-steps", options.worst_steps,
                   "Also list the N steps with the largest error, each with the ATE the "
                   "estimate would have with that step from the ground truth")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  traj->add_option("--max-difference", options.max_difference,
                   "Largest timestamp difference of a matched pose pair [s]")
      ->check(finite_number())
      ->capture_default_str();
  traj->add_option("--offset", options.offset,
                   "Seconds added to the estimate's timestamps before matching (its clock's lag "
                   "behind the ground truth's, as TUM's associate.py --offset); auto: measured "
                   "from how fast both trajectories turn (within +-0.5 s)")
      ->check(finite_number_or("auto"))
      ->capture_default_str();

  CLI::App* planes = add_metric("planes", "SegComp scores of a plane label image",
                                "Ground-truth labels (16-bit PNG, 0 = none)",
                                "Predicted labels (16-bit PNG, 0 = none)");
  planes->add_option("--threshold", options.threshold, "Overlap threshold T, in (0.5, 1]")
      ->check(finite_in(0.5, 1.0))
      ->capture_default_str();

  CLI::App* rooms =
      add_metric("rooms", "Recall, precision and MCC of a room segmentation",
                 "Ground-truth rooms: an ipa *_gt_segmentation.png (8-bit) or a 16-bit label PNG",
                 "Segmentation: a 16-bit label PNG (an 8-bit drawing is read like GT)");
  rooms
      ->add_option("--resolution", options.resolution,
                   "Metres per cell: regions of at most 0.25 m^2 are left out (ipa's 100 cells "
                   "at 0.05 m)")
      ->check(finite_positive())
      ->capture_default_str();
  add_metric("semantic", "Confusion matrix, IoU and accuracy of semantic classes",
             "Ground truth: 8-bit PNG of SemanticClass values",
             "Prediction: 8-bit PNG of SemanticClass values");
  return eval;
}

int run_eval_command(const EvalOptions& options, std::ostream& out) {
  const io::MetricReport report = options.metric == "traj"     ? trajectory_report(options)
                                  : options.metric == "planes" ? plane_report(options)
                                  : options.metric == "rooms"  ? room_report(options)
                                                               : semantic_report(options);
  out << (options.json ? report.json() : report.table());
  return 0;
}

}  // namespace kartograf::cli
