#include "outputs/map_report_html.hpp"

#include <sstream>

#include "outputs/html_text.hpp"
#include "outputs/report_assets.hpp"
#include "outputs/report_svg.hpp"
#include "kartograf/outputs/map_outputs.hpp"
#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::io::detail {

namespace {

std::string page_head(const Json& report) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         "<title>Kartograf map: " +
         html_escape(text_of(report["sequence"])) + "</title>\n<style>" +
         std::string(report_css()) + "</style>\n<script>" + inline_script(report_checks_js()) +
         "</script>\n</head>\n<body>\n<header><h1>Kartograf map</h1><p><code>" +
         html_escape(text_of(report["sequence"])) + "</code></p></header>\n<main>\n";
}

std::string colour_css(const Rgb8& c) {
  return "rgb(" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) +
         ")";
}

// The grid classes' colours, for evaluation.png (semantic.png carries its own legend).
std::string class_legend() {
  std::string html = "<span class=\"legend\">";
  for (const SemanticClass c :
       {SemanticClass::floor, SemanticClass::wall, SemanticClass::door, SemanticClass::furniture})
    html += "<i style=\"background:" + colour_css(semantic::class_colour(c)) + "\"></i>" +
            std::string(to_string(c)) + " ";
  return html + "<i style=\"background:" + colour_css(semantic::kUnobservedColour) +
         "\"></i>unobserved</span>";
}

void figure(std::ostringstream& html, const std::string& file, const std::string& caption_html,
            const char* css_class = "") {
  html << "<figure class=\"" << css_class << "\"><a href=\"" << file << "\"><img src=\"" << file
       << "\" alt=\"" << file << "\"></a><figcaption><b>" << file << "</b>: " << caption_html
       << "</figcaption></figure>\n";
}

std::string pictures_section(const MapReportInput& in) {
  const bool truth = in.evaluation && !in.evaluation->frame_errors.empty();
  std::ostringstream html;
  html << "<section id=\"pictures\">\n<h2>Pictures</h2>\n<div class=\"pictures\">\n";
  figure(html, "top_view.png",
         std::string("the map from above; the estimated camera path in red (start green, end "
                     "blue)") +
             (truth ? ", the true path in yellow" : ""));
  figure(html, "semantic.png", "the metric-semantic grid (legend below it)", "grid");
  figure(html, "rooms.png", "the rooms in colour over the occupancy grid", "grid");
  if (in.evaluation_picture)
    figure(html, "evaluation.png",
           "the truth (top) and ours (bottom) on the floor plan's cells: classes left (" +
               class_legend() + "), rooms right",
           "grid");
  figure(html, "occupancy.png", "occupancy: free white, occupied black, unknown grey", "grid");
  html << "</div>\n</section>\n";
  return html.str();
}

std::string error_plot(const MapReportInput& in) {
  if (!in.evaluation || in.evaluation->frame_errors.empty()) return "";
  PlotSeries error{"error", "#d62728", {}};
  for (const pipeline::FrameTrajectoryError& f : in.evaluation->frame_errors)
    error.points.emplace_back(static_cast<double>(f.frame), 100 * f.error_m);
  PlotAxes axes;
  axes.x_label = "frame";
  axes.y_label = "error [cm]";
  const double rmse = 100 * in.evaluation->trajectory->ate.translation_m.rmse;
  axes.y_reference = {rmse, "RMSE " + format_number(rmse, "%.2f") + " cm"};
  return "<figure class=\"plot\">" + svg_line_plot({error}, axes) +
         "<figcaption>Trajectory error per frame: the distance between the true camera position "
         "and ours after the ATE's SE(3) alignment.</figcaption></figure>\n";
}

std::string stage_plot(const Json& report) {
  const double total = report["timing_s"]["total"].get<double>();
  std::vector<Bar> bars;
  for (const Json& stage : report["timing_s"]["stages"]) {
    const double s = stage["seconds"].get<double>();
    bars.push_back({text_of(stage["stage"]), s,
                    format_number(s, "%.2f") + " s (" +
                        format_number(total > 0 ? 100 * s / total : 0, "%.0f") + " %)"});
  }
  return "<figure class=\"plot\">" + svg_bar_chart(bars) + "<figcaption>Time per stage, " +
         format_number(total, "%.1f") + " s in total.</figcaption></figure>\n";
}

// A two-column table of a JSON object's scalar members (nested objects flattened a.b).
void value_rows(std::ostringstream& html, const Json& object, const std::string& prefix = "") {
  for (const auto& [key, value] : object.items()) {
    const std::string name = prefix.empty() ? key : prefix + "." + key;
    if (value.is_object()) {
      value_rows(html, value, name);
    } else if (!value.is_array()) {
      html << "<tr><td>" << html_escape(name) << "</td><td>"
           << (value.is_number_float() ? format_number(value.get<double>(), "%.4f")
                                       : html_escape(text_of(value)))
           << "</td></tr>\n";
    }
  }
}

std::string details_section(const MapReportInput& in) {
  std::ostringstream html;
  html << "<section id=\"details\">\n<details><summary>All values (report.json)</summary>\n"
       << "<table class=\"values\">\n";
  value_rows(html, in.report);
  html << "</table></details>\n<h2>Files</h2>\n<ul class=\"files\">\n";
  for (const std::string& file : map_output_files())
    html << "<li><a href=\"" << file << "\">" << file << "</a></li>\n";
  if (in.evaluation_picture) html << "<li><a href=\"evaluation.png\">evaluation.png</a></li>\n";
  html << "</ul>\n</section>\n";
  return html.str();
}

}  // namespace

const Json* report_member(const Json& report, std::initializer_list<const char*> path) {
  const Json* at = &report;
  for (const char* key : path) {
    if (!at->is_object() || !at->contains(key) || (*at)[key].is_null()) return nullptr;
    at = &(*at)[key];
  }
  return at;
}

std::string text_of(const Json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

std::string map_report_html(const MapReportInput& input) {
  std::string html = page_head(input.report);
  html += report_summary_section(input);
  html += report_metrics_section(input);
  html += pictures_section(input);
  html += "<section id=\"plots\">\n<h2>Over time</h2>\n" + error_plot(input) +
          stage_plot(input.report) + "</section>\n";
  html += report_confusion_section(input.report);
  html += report_scene_section(input);
  html += details_section(input);
  html += "</main>\n" + report_scene_scripts() + "</body></html>\n";
  return html;
}

}  // namespace kartograf::io::detail
