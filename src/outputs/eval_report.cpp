#include "kartograf/outputs/eval_report.hpp"

#include <charconv>
#include <cstdio>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

namespace kartograf::io {

struct MetricReport::Json {
  nlohmann::ordered_json object = nlohmann::ordered_json::object();
};

MetricReport::MetricReport(std::string title)
    : title_(std::move(title)), json_(std::make_unique<Json>()) {}
MetricReport::MetricReport(MetricReport&&) noexcept = default;
MetricReport& MetricReport::operator=(MetricReport&&) noexcept = default;
MetricReport::~MetricReport() = default;

void MetricReport::note(std::string line) {
  notes_.push_back(std::move(line));
}

void MetricReport::add(const std::string& key, double value, std::string meaning) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", value);
  json_->object[key] = value;
  rows_.push_back({key, text, std::move(meaning)});
}

void MetricReport::add(const std::string& key, std::int64_t value, std::string meaning) {
  json_->object[key] = value;
  rows_.push_back({key, std::to_string(value), std::move(meaning)});
}

void MetricReport::add(const std::string& key, int value, std::string meaning) {
  add(key, std::int64_t{value}, std::move(meaning));
}

void MetricReport::add(const std::string& key, const std::optional<double>& value,
                       std::string meaning) {
  if (value) return add(key, *value, std::move(meaning));
  json_->object[key] = nullptr;
  rows_.push_back({key, "-", std::move(meaning)});
}

void MetricReport::add_text(const std::string& key, const std::string& value) {
  json_->object[key] = value;
}

void MetricReport::add_number(const std::string& key, double value) {
  json_->object[key] = value;
}

void MetricReport::add_matrix(const std::string& key,
                              const std::vector<std::vector<std::int64_t>>& rows) {
  nlohmann::ordered_json matrix = nlohmann::ordered_json::array();
  for (const std::vector<std::int64_t>& row : rows) {
    nlohmann::ordered_json values = nlohmann::ordered_json::array();
    for (const std::int64_t value : row) values.push_back(value);
    matrix.push_back(std::move(values));
  }
  json_->object[key] = std::move(matrix);
}

void MetricReport::add_records(const std::string& key, const std::vector<std::string>& columns,
                               const std::vector<std::vector<double>>& rows) {
  nlohmann::ordered_json records = nlohmann::ordered_json::array();
  for (const std::vector<double>& row : rows) {
    nlohmann::ordered_json record = nlohmann::ordered_json::object();
    for (std::size_t c = 0; c < columns.size() && c < row.size(); ++c) record[columns[c]] = row[c];
    records.push_back(std::move(record));
  }
  json_->object[key] = std::move(records);
}

void MetricReport::add_block(std::string text) {
  blocks_.push_back(std::move(text));
}

std::string MetricReport::table() const {
  std::string text = title_ + "\n";
  for (const std::string& line : notes_) text += "  " + line + "\n";
  for (const Row& row : rows_) {
    char line[512];
    std::snprintf(line, sizeof(line), "%-20s %14s   %s\n", row.key.c_str(), row.text.c_str(),
                  row.meaning.c_str());
    text += line;
  }
  for (const std::string& block : blocks_) text += block;
  return text;
}

std::string MetricReport::json() const {
  return json_->object.dump() + "\n";
}

namespace {

std::int64_t count(std::size_t n) {
  return static_cast<std::int64_t>(n);
}

// Shortest text that reads back as the same number: 0.02, 1, 0.8.
std::string number_text(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

// "ground truth <GT>, <predicted_as> <file>" under the title.
MetricReport image_pair_report(std::string title, const std::string& ground_truth_file,
                               const std::string& predicted_file,
                               const std::string& predicted_as = "prediction") {
  MetricReport report(std::move(title));
  report.note("ground truth " + ground_truth_file + ", " + predicted_as + " " + predicted_file);
  return report;
}

// The offset added to the estimate's timestamps: a row, and a note where it was measured.
void add_time_offset(MetricReport& report, const TimeOffset& offset) {
  report.add("time_offset_s", offset.seconds, "seconds added to the estimate's timestamps");
  if (!offset.measured) return;
  const eval::ClockOffsetEstimate& m = *offset.measured;
  char line[200];
  std::snprintf(line, sizeof(line),
                "time offset measured from the turning rates (--offset auto): %+.4f s +- %.1f ms "
                "over %zu steps, rotation disagreement %.3f deg a step (%.3f at 0)",
                m.offset_s, 1000 * m.sigma_s, m.steps, m.rms_deg, m.given_rms_deg);
  report.note(line);
  report.add_number("time_offset_sigma_s", m.sigma_s);
}

}  // namespace

MetricReport trajectory_report(const eval::TrajectoryEvaluation& result,
                               const TrajectoryReportInput& input) {
  const eval::ErrorStatistics& ate = result.ate.translation_m;
  const bool seconds = input.delta_unit == "seconds";
  const std::string delta = number_text(input.delta) + (seconds ? " s" : " frame(s)");
  MetricReport report("trajectory evaluation (TUM RGB-D benchmark ATE and RPE)");
  report.note("ground truth " + input.ground_truth_file + " (" +
              std::to_string(input.ground_truth_poses) + " poses), estimate " +
              input.estimate_file + " (" + std::to_string(input.estimate_poses) + " poses)");
  report.note(std::to_string(input.matched_poses) + " pose pairs matched within " +
              number_text(input.max_difference_s) + " s; alignment " +
              (input.sim3 ? "Sim(3)" : "SE(3)"));
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
  report.add("matched_poses", count(input.matched_poses), "pose pairs matched by timestamp");
  add_time_offset(report, input.offset);
  report.add("scale", result.ate.alignment.scale, "scale of the alignment (1 unless --sim3)");
  report.add_text("alignment", input.sim3 ? "sim3" : "se3");
  report.add_number("delta", input.delta);
  report.add_text("delta_unit", input.delta_unit);
  return report;
}

void add_worst_steps(MetricReport& report, const eval::WorstSteps& worst) {
  report.add("ate_true_steps_m", worst.ate_rmse_with_true_steps_m,
             "ATE RMSE with the " + std::to_string(worst.steps.size()) +
                 " worst steps from the ground truth");
  std::string block =
      "worst steps (largest translation error first; ATE RMSE with that step "
      "from the ground truth):\n";
  std::vector<std::vector<double>> rows;
  for (const eval::StepError& step : worst.steps) {
    char line[160];
    std::snprintf(line, sizeof(line), "  pose %6zu  t %14.6f  %9.2f mm  %7.3f deg  ATE %.4f m\n",
                  step.pose, step.timestamp, 1000 * step.translation_m, step.rotation_deg,
                  step.ate_rmse_with_true_step_m);
    block += line;
    rows.push_back({static_cast<double>(step.pose), step.timestamp, step.translation_m,
                    step.rotation_deg, step.ate_rmse_with_true_step_m});
  }
  report.add_block(std::move(block));
  report.add_records(
      "worst_steps",
      {"pose", "timestamp", "translation_m", "rotation_deg", "ate_rmse_with_true_step_m"}, rows);
}

MetricReport plane_report(const eval::SegCompResult& result, const std::string& ground_truth_file,
                          const std::string& prediction_file, double threshold) {
  MetricReport report =
      image_pair_report("plane segmentation (SegComp, Hoover et al. 1996), overlap threshold " +
                            number_text(threshold),
                        ground_truth_file, prediction_file);
  report.add("ground_truth_regions", result.ground_truth_regions, "regions in the ground truth");
  report.add("predicted_regions", result.predicted_regions, "regions in the prediction");
  report.add("correct", result.correct, "correct detections");
  report.add("over_segmented", result.over_segmented, "ground-truth regions split into several");
  report.add("under_segmented", result.under_segmented,
             "predicted regions merging several ground-truth regions");
  report.add("missed", result.missed, "ground-truth regions not found");
  report.add("noise", result.noise, "predicted regions matching nothing");
  report.add_number("threshold", threshold);
  return report;
}

MetricReport room_report(const eval::RoomSegmentationScores& scores,
                         const std::string& ground_truth_file,
                         const std::string& segmentation_file) {
  MetricReport report =
      image_pair_report("room segmentation (ipa_room_segmentation recall/precision, MAORIS MCC)",
                        ground_truth_file, segmentation_file, "segmentation");
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

namespace {

// The confusion matrix as a table for people (rows: ground truth), and its counts.
std::string confusion_table(const eval::SemanticScores& scores,
                            std::vector<std::vector<std::int64_t>>& counts) {
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
    std::vector<std::int64_t>& row = counts.emplace_back();
    for (int predicted_class = 0; predicted_class < kSemanticClassCount; ++predicted_class) {
      const std::int64_t n = scores.confusion(gt, predicted_class);
      std::snprintf(cell, sizeof(cell), "%11lld", static_cast<long long>(n));
      table += cell;
      row.push_back(n);
    }
  }
  return table + "\n";
}

}  // namespace

MetricReport semantic_report(const eval::SemanticScores& scores,
                             const std::string& ground_truth_file,
                             const std::string& prediction_file) {
  MetricReport report =
      image_pair_report("semantic segmentation (pixels with unknown ground truth ignored)",
                        ground_truth_file, prediction_file);
  report.add("overall_accuracy", scores.overall_accuracy, "correctly classified pixels");
  report.add("mean_iou", scores.mean_iou, "mean intersection over union of the classes present");
  for (int c = 1; c < kSemanticClassCount; ++c) {
    const std::string name(kSemanticClassNames[c]);
    report.add("iou_" + name, scores.iou[c], "IoU of " + name + " (-: in neither image)");
  }
  report.add("evaluated_pixels", scores.evaluated_pixels, "pixels with known ground truth");
  std::vector<std::vector<std::int64_t>> counts;
  report.add_block(confusion_table(scores, counts));
  report.add_matrix("confusion", counts);
  return report;
}

}  // namespace kartograf::io
