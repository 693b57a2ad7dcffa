// report.html: each metric against ground truth with its value, how it compares and its target;
// the class confusion as a matrix.
#include <cmath>
#include <optional>
#include <sstream>

#include "outputs/html_text.hpp"
#include "outputs/map_report_html.hpp"

namespace kartograf::io::detail {

namespace {

// Issue 8's targets for the default synthetic building (docs/user-guide.md).
struct Target {
  bool at_most = false;  // else at least
  double value = 0;
  std::string text;
};

struct MetricRow {
  std::string name, value, compare;  // HTML
  std::optional<double> score;       // compared with the target
  std::optional<Target> target;
};

void metric_row(std::ostringstream& html, const MetricRow& row) {
  std::string target, verdict;
  if (row.target && row.score) {
    const bool met =
        row.target->at_most ? *row.score <= row.target->value : *row.score >= row.target->value;
    target = html_escape(row.target->text);
    verdict = met ? " met" : " missed";
  }
  html << "<tr><th>" << row.name << "</th><td class=\"value" << verdict << "\">" << row.value
       << "</td><td>" << row.compare << "</td><td class=\"target\">" << target << "</td></tr>\n";
}

double path_length(const std::vector<Eigen::Isometry3d>& poses) {
  double length = 0;
  for (std::size_t i = 1; i < poses.size(); ++i)
    length += (poses[i].translation() - poses[i - 1].translation()).norm();
  return length;
}

void trajectory_rows(std::ostringstream& html, const Json& t, const MapReportInput& in) {
  const double ate = t["ate_rmse_m"].get<double>(), length = path_length(in.result.poses);
  const double step =
      in.result.poses.size() > 1 ? length / static_cast<double>(in.result.poses.size() - 1) : 0.0;
  std::string share;
  if (length > 0)
    share = format_number(100 * ate / length, "%.2f") + " % of the " + format_length(length) +
            " path; ";
  metric_row(html, {"trajectory: ATE RMSE", format_length(ate),
                    share + "max " + format_length(t["ate_max_m"].get<double>()) + " over " +
                        t["poses"].dump() + " poses (after an SE(3) alignment)",
                    ate, Target{true, 0.01, "≤ 1 cm"}});
  metric_row(html, {"trajectory: RPE per frame, translation",
                    format_length(t["rpe_translation_rmse_m"].get<double>()),
                    "RMSE; the camera moves " + format_length(step) + " per frame on average",
                    std::nullopt, std::nullopt});
  metric_row(html, {"trajectory: RPE per frame, rotation",
                    format_number(t["rpe_rotation_rmse_deg"].get<double>(), "%.2f") + "&deg;",
                    "RMSE", std::nullopt, std::nullopt});
}

// The odometry's own ATE (before loop closure) beside the SLAM's: what the back end adds.
void odometry_row(std::ostringstream& html, const Json& odometry, const Json& slam) {
  const double before = odometry["ate_rmse_m"].get<double>();
  const double after = slam["ate_rmse_m"].get<double>();
  std::string change = "before loop closure and pose-graph optimisation";
  if (before > 0)
    change += "; the back end changes the ATE by " +
              format_number(100 * (after - before) / before, "%+.0f") + " %";
  metric_row(html, {"odometry alone: ATE RMSE", format_length(before), change, std::nullopt,
                    std::nullopt});
}

// Where the ground truth interpolates between measured poses (SUN3D's every 5th frame).
void measured_poses_row(std::ostringstream& html, const Json& measured) {
  metric_row(html,
             {"ATE RMSE at the measured poses", format_length(measured["ate_rmse_m"].get<double>()),
              "the ground truth measured every " + measured["ground_truth_period"].dump() +
                  " frames (" + measured["poses"].dump() +
                  " poses) and interpolated between: the ATE above scores the estimate "
                  "against that interpolation too",
              std::nullopt, std::nullopt});
}

void rooms_rows(std::ostringstream& html, const Json& r) {
  metric_row(html,
             {"rooms found / true", r["segments"].dump() + " / " + r["ground_truth_rooms"].dump(),
              "rooms larger than 100 cells", std::nullopt, std::nullopt});
  for (const char* kind : {"recall", "precision"}) {
    const double mean = r[std::string(kind) + "_mean"].get<double>();
    metric_row(html,
               {std::string("rooms ") + kind + " (ipa, mean)", format_number(mean),
                "area-weighted " + format_number(r[std::string(kind) + "_total"].get<double>()) +
                    "; 1 is perfect",
                mean, Target{false, 0.9, "≥ 0.9"}});
  }
  metric_row(html, {"rooms MCC (MAORIS)", format_number(r["mcc"].get<double>()),
                    "1: every true room matched by exactly one room", std::nullopt, std::nullopt});
}

void classes_rows(std::ostringstream& html, const Json& c) {
  for (const auto& [name, iou] : c["iou"].items()) {
    if (iou.is_null()) continue;
    std::string cells;
    if (const Json* row = report_member(c, {"confusion", name.c_str()})) {
      std::int64_t count = 0;
      for (const auto& [ours, n] : row->items()) count += n.get<std::int64_t>();
      cells = std::to_string(count) + " true cells";
    }
    std::optional<Target> target;
    if (name == "door") target = Target{false, 0.8, "≥ 0.8"};
    metric_row(html, {"IoU " + html_escape(name), format_number(iou.get<double>()), cells,
                      iou.get<double>(), target});
  }
  metric_row(html, {"classes: mean IoU", format_number(c["mean_iou"].get<double>()),
                    "over the classes above", std::nullopt, std::nullopt});
  metric_row(html, {"classes: overall accuracy", format_number(c["overall_accuracy"].get<double>()),
                    c["cells"].dump() + " plan cells scored; unobserved cells count as errors",
                    std::nullopt, std::nullopt});
}

// Row-normalised shading: the share of a true class's cells given each of our classes.
std::string confusion_cell(std::int64_t count, std::int64_t row_total, bool diagonal) {
  const double share = row_total > 0 ? static_cast<double>(count) / row_total : 0.0;
  const std::string colour = diagonal ? "34,139,84" : "200,60,50";
  return "<td" + std::string(diagonal ? " class=\"diagonal\"" : "") + " style=\"background:rgba(" +
         colour + "," + format_number(0.08 + 0.85 * share, "%.2f") + ")\" title=\"" +
         format_number(100 * share, "%.1f") + " % of the row\">" + std::to_string(count) +
         "<small>" + format_number(100 * share, "%.0f") + " %</small></td>";
}

}  // namespace

std::string report_metrics_section(const MapReportInput& input) {
  std::ostringstream html;
  html << "<section id=\"metrics\">\n<h2>Metrics against ground truth</h2>\n";
  const Json* e = report_member(input.report, {"evaluation"});
  if (!e)
    return html.str() +
           "<p>The sequence has no ground truth: nothing to compare with.</p>\n</section>\n";
  html << "<table class=\"metrics\"><tr><th>metric</th><th>value</th><th>how it compares</th>"
       << "<th>target</th></tr>\n";
  if (const Json* t = report_member(*e, {"trajectory"})) {
    trajectory_rows(html, *t, input);
    if (const Json* o = report_member(*e, {"odometry_trajectory"})) odometry_row(html, *o, *t);
    if (const Json* m = report_member(*e, {"trajectory_at_measured_poses"}))
      measured_poses_row(html, *m);
  }
  if (const Json* r = report_member(*e, {"rooms"})) rooms_rows(html, *r);
  if (const Json* c = report_member(*e, {"classes"})) classes_rows(html, *c);
  html
      << "</table>\n<p class=\"note\">Targets: issue 8's for the default synthetic building "
      << "(docs/user-guide.md); green: met, red: missed. On other data they are a yardstick.</p>\n";
  for (const Json& reason : (*e)["not_scored"])
    html << "<p class=\"note\">Not scored: " << html_escape(text_of(reason)) << "</p>\n";
  return html.str() + "</section>\n";
}

std::string report_confusion_section(const Json& report) {
  const Json* confusion = report_member(report, {"evaluation", "classes", "confusion"});
  if (!confusion) return "";
  std::ostringstream html;
  html << "<section id=\"confusion\">\n<h2>Class confusion</h2>\n<p class=\"note\">Plan cells by "
       << "true class (rows) and our class (columns); shading: the share of the row.</p>\n"
       << "<table class=\"confusion\"><tr><th>true \\ ours</th>";
  for (const auto& [ours, unused] : confusion->begin().value().items())
    html << "<th>" << html_escape(ours) << "</th>";
  html << "</tr>\n";
  for (const auto& [truth, row] : confusion->items()) {
    std::int64_t total = 0;
    for (const auto& [ours, count] : row.items()) total += count.get<std::int64_t>();
    if (total == 0) continue;  // a class the plan does not have
    html << "<tr><th>" << html_escape(truth) << "</th>";
    for (const auto& [ours, count] : row.items())
      html << confusion_cell(count.get<std::int64_t>(), total, ours == truth);
    html << "</tr>\n";
  }
  html << "</table>\n</section>\n";
  return html.str();
}

}  // namespace kartograf::io::detail
