#pragma once
// `kartograf eval`'s reports: rows of (key, value, meaning), printed as a table for people or as
// one JSON object with the same keys for scripts, built from kartograf::eval's results.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/eval/clock_offset.hpp"
#include "kartograf/eval/plane_metrics.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/eval/semantic_metrics.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"

namespace kartograf::io {

class MetricReport {
 public:
  explicit MetricReport(std::string title);
  MetricReport(MetricReport&&) noexcept;
  MetricReport& operator=(MetricReport&&) noexcept;
  ~MetricReport();

  void note(std::string line);  // a line under the title (table only)
  // A row: "%.6f" in the table; an optional without a value is "-" in the table, null in JSON.
  void add(const std::string& key, double value, std::string meaning);
  void add(const std::string& key, std::int64_t value, std::string meaning);
  void add(const std::string& key, int value, std::string meaning);
  void add(const std::string& key, const std::optional<double>& value, std::string meaning);
  // JSON only: a string, a number, a matrix of counts.
  void add_text(const std::string& key, const std::string& value);
  void add_number(const std::string& key, double value);
  void add_matrix(const std::string& key, const std::vector<std::vector<std::int64_t>>& rows);
  // JSON only: an array of objects, one per row, with the columns' names as keys.
  void add_records(const std::string& key, const std::vector<std::string>& columns,
                   const std::vector<std::vector<double>>& rows);
  void add_block(std::string text);  // table only: text after the rows, as it is

  std::string table() const;
  std::string json() const;  // one line, with its newline

 private:
  struct Row {
    std::string key, text, meaning;
  };
  struct Json;  // the JSON object (nlohmann, private to the outputs library)

  std::string title_;
  std::vector<std::string> notes_;
  std::vector<Row> rows_;
  std::vector<std::string> blocks_;
  std::unique_ptr<Json> json_;
};

// Seconds added to an estimate's timestamps before matching, and how they were measured where
// they were (eval::estimate_clock_offset).
struct TimeOffset {
  double seconds = 0;
  std::optional<eval::ClockOffsetEstimate> measured;
};

// A trajectory's ATE and RPE (eval::evaluate_trajectory) and what it was computed from.
struct TrajectoryReportInput {
  std::string ground_truth_file, estimate_file;
  std::size_t ground_truth_poses = 0, estimate_poses = 0, matched_poses = 0;
  double max_difference_s = 0;  // of a matched pair's timestamps
  TimeOffset offset;
  bool sim3 = false;       // the alignment: Sim(3), else SE(3)
  double delta = 1;        // the RPE's step
  std::string delta_unit;  // frames | seconds
};
MetricReport trajectory_report(const eval::TrajectoryEvaluation& result,
                               const TrajectoryReportInput& input);
// The steps that carry the error (eval::worst_steps): a row of the ATE with all of them from the
// ground truth, the steps themselves as a block in the table and an array in JSON.
void add_worst_steps(MetricReport& report, const eval::WorstSteps& worst);

// Reports on a pair of images, noting both files.
MetricReport plane_report(const eval::SegCompResult& result, const std::string& ground_truth_file,
                          const std::string& prediction_file, double threshold);
MetricReport room_report(const eval::RoomSegmentationScores& scores,
                         const std::string& ground_truth_file,
                         const std::string& segmentation_file);
MetricReport semantic_report(const eval::SemanticScores& scores,
                             const std::string& ground_truth_file,
                             const std::string& prediction_file);

}  // namespace kartograf::io
