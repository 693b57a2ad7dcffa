// `kartograf eval traj|planes|rooms|semantic`: reads the files, calls kartograf::eval, prints a
// table (or one JSON object with --json). No metric is computed here.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/tum.hpp"
#include "option_checks.hpp"

namespace kartograf::cli {

namespace {

using Json = nlohmann::ordered_json;

// Rows of (key, value, meaning): printed as a table, or as one JSON object with the same keys.
class Report {
 public:
  explicit Report(std::string title) : title_(std::move(title)) {}

  void note(std::string line) { notes_.push_back(std::move(line)); }
  void add(const std::string& key, double value, std::string meaning) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.6f", value);
    add_row(key, value, text, std::move(meaning));
  }
  void add(const std::string& key, std::int64_t value, std::string meaning) {
    add_row(key, value, std::to_string(value), std::move(meaning));
  }
  void add(const std::string& key, int value, std::string meaning) {
    add(key, std::int64_t{value}, std::move(meaning));
  }
  void add(const std::string& key, const std::optional<double>& value, std::string meaning) {
    if (value) return add(key, *value, std::move(meaning));
    add_row(key, nullptr, "-", std::move(meaning));
  }
  void add_text(const std::string& key, const std::string& value) { json_[key] = value; }
  void add_json(const std::string& key, Json value) { json_[key] = std::move(value); }
  void add_block(std::string text) { blocks_.push_back(std::move(text)); }

  void print(std::ostream& out, bool as_json) const {
    if (as_json) {
      out << json_.dump() << "\n";
      return;
    }
    out << title_ << "\n";
    for (const std::string& line : notes_) out << "  " << line << "\n";
    for (const Row& row : rows_) {
      char line[512];
      std::snprintf(line, sizeof(line), "%-20s %14s   %s\n", row.key.c_str(), row.text.c_str(),
                    row.meaning.c_str());
      out << line;
    }
    for (const std::string& block : blocks_) out << block;
  }

 private:
  struct Row {
    std::string key, text, meaning;
  };
  void add_row(const std::string& key, Json value, std::string text, std::string meaning) {
    json_[key] = std::move(value);
    rows_.push_back({key, std::move(text), std::move(meaning)});
  }

  std::string title_;
  std::vector<std::string> notes_;
  std::vector<Row> rows_;
  std::vector<std::string> blocks_;
  Json json_ = Json::object();
};

std::int64_t count(std::size_t n) {
  return static_cast<std::int64_t>(n);
}

// Shortest text that reads back as the same number: 0.02, 1, 0.8.
std::string number_text(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

// The report on a pair of images, noting both files: "ground truth <GT>, <predicted_as> <file>".
Report image_pair_report(std::string title, const EvalOptions& options,
                         const std::string& predicted_as = "prediction") {
  Report report(std::move(title));
  report.note("ground truth " + options.ground_truth.string() + ", " + predicted_as + " " +
              options.prediction.string());
  return report;
}

std::vector<double> timestamps(const Trajectory& trajectory) {
  std::vector<double> times;
  times.reserve(trajectory.size());
  for (const StampedPose& pose : trajectory) times.push_back(pose.timestamp);
  return times;
}

Report trajectory_report(const EvalOptions& options) {
  const Trajectory ground_truth = io::read_tum_trajectory(options.ground_truth);
  const Trajectory estimate = io::read_tum_trajectory(options.prediction);
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
  const eval::ErrorStatistics& ate = result.ate.translation_m;
  const std::string delta = number_text(options.delta) + (seconds ? " s" : " frame(s)");

  Report report("trajectory evaluation (TUM RGB-D benchmark ATE and RPE)");
  report.note("ground truth " + options.ground_truth.string() + " (" +
              std::to_string(ground_truth.size()) + " poses), estimate " +
              options.prediction.string() + " (" + std::to_string(estimate.size()) + " poses)");
  report.note(std::to_string(matched.size()) + " pose pairs matched within " +
              number_text(options.max_difference) + " s; alignment " +
              (options.sim3 ? "Sim(3)" : "SE(3)"));
  report.add("ate_rmse_m", ate.rmse, "absolute trajectory error after alignment, RMSE");
  report.add("ate_mean_m", ate.mean, "ATE mean");
  report.add("ate_median_m", ate.median, "ATE median");
  report.add("ate_std_m", ate.std_dev, "ATE standard deviation");
  report.add("ate_min_m", ate.min, "ATE minimum");
  report.add("ate_max_m", ate.max, "ATE maximum");
  report.add("rpe_trans_m", result.rpe.translation_m.rmse,
             "relative pose error over " + delta + ", translation RMSE");
  report.add("rpe_rot_deg", result.rpe.rotation_deg.rmse, "RPE rotation RMSE [deg]");
  report.add("rpe_pairs", count(result.rpe.translation_m.count), "pose pairs in the RPE");
  report.add("matched_poses", count(matched.size()), "pose pairs matched by timestamp");
  report.add("scale", result.ate.alignment.scale, "scale of the alignment (1 unless --sim3)");
  report.add_text("alignment", options.sim3 ? "sim3" : "se3");
  report.add_json("delta", options.delta);
  report.add_text("delta_unit", options.delta_unit);
  return report;
}

Report plane_report(const EvalOptions& options) {
  const LabelImage ground_truth = io::read_label_png(options.ground_truth);
  const LabelImage predicted = io::read_label_png(options.prediction);
  const eval::SegCompResult result =
      eval::compare_plane_segmentations(ground_truth, predicted, {options.threshold});
  Report report =
      image_pair_report("plane segmentation (SegComp, Hoover et al. 1996), overlap threshold " +
                            number_text(options.threshold),
                        options);
  report.add("ground_truth_regions", result.ground_truth_regions, "regions in the ground truth");
  report.add("predicted_regions", result.predicted_regions, "regions in the prediction");
  report.add("correct", result.correct, "correct detections");
  report.add("over_segmented", result.over_segmented, "ground-truth regions split into several");
  report.add("under_segmented", result.under_segmented,
             "predicted regions merging several ground-truth regions");
  report.add("missed", result.missed, "ground-truth regions not found");
  report.add("noise", result.noise, "predicted regions matching nothing");
  report.add_json("threshold", options.threshold);
  return report;
}

Report room_report(const EvalOptions& options) {
  const LabelImage ground_truth = io::read_ground_truth_rooms(options.ground_truth);
  const LabelImage segmentation = io::read_ground_truth_rooms(options.prediction);
  const eval::RoomSegmentationScores scores =
      eval::evaluate_room_segmentation(ground_truth, segmentation);
  Report report =
      image_pair_report("room segmentation (ipa_room_segmentation recall/precision, MAORIS MCC)",
                        options, "segmentation");
  report.add("recall_mean", scores.recall_mean, "mean over rooms of best overlap / room area");
  report.add("recall_total", scores.recall_total, "the same, area-weighted");
  report.add("precision_mean", scores.precision_mean,
             "mean over segments of best overlap / segment area");
  report.add("precision_total", scores.precision_total, "the same, area-weighted");
  report.add("mcc", scores.mcc, "Matthews correlation coefficient (MAORIS)");
  report.add("ground_truth_rooms", scores.ground_truth_rooms, "rooms of > 100 pixels");
  report.add("segments", scores.segments, "segments of > 100 pixels");
  return report;
}

Report semantic_report(const EvalOptions& options) {
  const SemanticImage ground_truth = io::read_semantic_png(options.ground_truth);
  const SemanticImage predicted = io::read_semantic_png(options.prediction);
  const eval::SemanticScores scores = eval::evaluate_semantic_segmentation(ground_truth, predicted);
  Report report = image_pair_report(
      "semantic segmentation (pixels with unknown ground truth ignored)", options);
  report.add("overall_accuracy", scores.overall_accuracy, "correctly classified pixels");
  report.add("mean_iou", scores.mean_iou, "mean intersection over union of the classes present");
  for (int c = 1; c < kSemanticClassCount; ++c) {
    const std::string name(kSemanticClassNames[c]);
    report.add("iou_" + name, scores.iou[c], "IoU of " + name + " (-: in neither image)");
  }
  report.add("evaluated_pixels", scores.evaluated_pixels, "pixels with known ground truth");

  Json confusion = Json::array();
  std::string table = "confusion matrix (rows: ground truth, columns: prediction):\n";
  char cell[32];
  std::snprintf(cell, sizeof(cell), "%-10s", "");
  table += cell;
  for (std::string_view name : kSemanticClassNames) {
    std::snprintf(cell, sizeof(cell), "%11.10s", std::string(name).c_str());
    table += cell;
  }
  for (int gt = 0; gt < kSemanticClassCount; ++gt) {
    std::snprintf(cell, sizeof(cell), "\n%-10s", std::string(kSemanticClassNames[gt]).c_str());
    table += cell;
    Json row = Json::array();
    for (int predicted_class = 0; predicted_class < kSemanticClassCount; ++predicted_class) {
      const std::int64_t n = scores.confusion(gt, predicted_class);
      std::snprintf(cell, sizeof(cell), "%11lld", static_cast<long long>(n));
      table += cell;
      row.push_back(n);
    }
    confusion.push_back(std::move(row));
  }
  report.add_block(table + "\n");
  report.add_json("confusion", std::move(confusion));
  return report;
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
  traj->add_option("--max-difference", options.max_difference,
                   "Largest timestamp difference of a matched pose pair [s]")
      ->check(finite_number())
      ->capture_default_str();

  CLI::App* planes = add_metric("planes", "SegComp scores of a plane label image",
                                "Ground-truth labels (16-bit PNG, 0 = none)",
                                "Predicted labels (16-bit PNG, 0 = none)");
  planes->add_option("--threshold", options.threshold, "Overlap threshold T, in (0.5, 1]")
      ->check(finite_in(0.5, 1.0))
      ->capture_default_str();

  add_metric("rooms", "Recall, precision and MCC of a room segmentation",
             "Ground-truth rooms: an ipa *_gt_segmentation.png (8-bit) or a 16-bit label PNG",
             "Segmentation: a 16-bit label PNG (an 8-bit drawing is read like GT)");
  add_metric("semantic", "Confusion matrix, IoU and accuracy of semantic classes",
             "Ground truth: 8-bit PNG of SemanticClass values",
             "Prediction: 8-bit PNG of SemanticClass values");
  return eval;
}

int run_eval_command(const EvalOptions& options, std::ostream& out) {
  Report report = options.metric == "traj"     ? trajectory_report(options)
                  : options.metric == "planes" ? plane_report(options)
                  : options.metric == "rooms"  ? room_report(options)
                                               : semantic_report(options);
  report.print(out, options.json);
  return 0;
}

}  // namespace kartograf::cli
