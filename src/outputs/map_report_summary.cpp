// report.html: the summary of the run (what was read, how long, what came out).
#include <algorithm>
#include <sstream>

#include "outputs/html_text.hpp"
#include "outputs/map_report_html.hpp"

namespace kartograf::io::detail {

namespace {

void fact(std::ostringstream& html, const std::string& name, const std::string& value_html) {
  html << "<tr><th>" << html_escape(name) << "</th><td>" << value_html << "</td></tr>\n";
}

std::string camera_text(const Json& camera) {
  std::string text = "f<sub>x</sub> " + format_number(camera["fx"].get<double>(), "%.1f") +
                     ", f<sub>y</sub> " + format_number(camera["fy"].get<double>(), "%.1f") +
                     ", c<sub>x</sub> " + format_number(camera["cx"].get<double>(), "%.1f") +
                     ", c<sub>y</sub> " + format_number(camera["cy"].get<double>(), "%.1f");
  if (camera.contains("width") && camera.contains("height"))
    text += "; " + text_of(camera["width"]) + " &times; " + text_of(camera["height"]);
  // The description names the source too (e.g. "file '...'"); the source alone where it is empty.
  std::string origin;
  for (const char* key : {"source", "description"})
    if (camera.contains(key) && !text_of(camera[key]).empty()) origin = text_of(camera[key]);
  return origin.empty() ? text
                        : text + " <span class=\"note\">(" + html_escape(origin) + ")</span>";
}

// The run's input: what was read, and how.
void input_facts(std::ostringstream& html, const Json& r) {
  fact(html, "sequence",
       "<code>" + html_escape(text_of(r["sequence"])) + "</code> (" +
           html_escape(text_of(r["layout"])) + ")");
  std::string frames = text_of(r["frames"]) + " frames";
  if (const Json* skipped = report_member(r, {"input", "frames_skipped"}); skipped && *skipped != 0)
    frames += ", " + text_of(*skipped) + " unreadable frames skipped";
  fact(html, "frames", frames);
  if (const Json* colour = report_member(r, {"input", "colour"}); colour && *colour == false)
    fact(html, "colour", "none: a depth camera alone (no local image features; a grey map)");
  const Json* camera = report_member(r, {"input", "camera"});
  if (!camera) camera = report_member(r, {"camera"});
  if (camera && camera->contains("fx")) fact(html, "camera", camera_text(*camera));
  const Json* depth = report_member(r, {"input", "depth_units_per_metre"});
  if (!depth) depth = report_member(r, {"depth_units_per_metre"});
  if (depth && depth->is_number() && depth->get<double>() > 0) {
    const std::string units = format_number(depth->get<double>(), "%g");
    std::string text = units + " depth units per metre";
    if (const Json* source = report_member(r, {"input", "depth_scale_source"})) {
      const std::string from = text_of(*source);  // e.g. "TUM: 5000 units per metre"
      if (!from.empty()) text += " (" + from.substr(0, from.find(": " + units + " ")) + ")";
    }
    fact(html, "depth scale", html_escape(text));
  }
  fact(html, "backend", html_escape(text_of(r["backend"]) + " (" + text_of(r["device"]) + ")"));
}

// ", poses 3, 5, 9 of trajectory.txt counting from 0" (the first 12 and how many more) from
// the list `key` of the slam section; empty where it has none (a report of an older version).
std::string poses_text(const Json& slam, const char* key) {
  if (!slam.contains(key) || slam[key].empty()) return "";
  constexpr std::size_t kShown = 12;
  const Json& poses = slam[key];
  std::string text = ", pose" + std::string(poses.size() > 1 ? "s " : " ");
  for (std::size_t i = 0; i < std::min(poses.size(), kShown); ++i)
    text += (i > 0 ? ", " : "") + text_of(poses[i]);
  if (poses.size() > kShown) text += " and " + std::to_string(poses.size() - kShown) + " more";
  return text + " of trajectory.txt counting from 0";
}

// What came out: time, map, rooms, views, loops.
void result_facts(std::ostringstream& html, const Json& r) {
  const double total = r["timing_s"]["total"].get<double>();
  const double frames = r["frames"].get<double>();
  fact(html, "time",
       format_number(total, "%.1f") + " s in total, " +
           format_number(total > 0 ? frames / total : 0, "%.1f") + " frames/s");
  std::string planes = text_of(r["planes"]["count"]) + " planes";
  std::string by_class;
  for (const auto& [label, count] : r["planes"]["by_class"].items())
    by_class += (by_class.empty() ? "" : ", ") + text_of(count) + " " + label;
  if (!by_class.empty()) planes += " (" + by_class + ")";
  fact(html, "map",
       text_of(r["slam"]["map_points"]) + " points; " + html_escape(planes) + "; grid " +
           text_of(r["grid"]["width"]) + " &times; " + text_of(r["grid"]["height"]) + " cells of " +
           format_number(100 * r["grid"]["resolution_m"].get<double>(), "%.0f") + " cm");
  fact(html, "rooms",
       text_of(r["rooms"]["count"]) + " (" + html_escape(text_of(r["rooms"]["method"])) + ")");
  const Json& views = r["views"];
  const int labelled = views["labelled"].get<int>(), unlabelled = views["unlabelled"].get<int>();
  std::string seen = std::to_string(labelled) + " of " + std::to_string(labelled + unlabelled);
  if (unlabelled > 0 && !text_of(views["first_unlabelled_reason"]).empty())
    seen += " <span class=\"note\">(first one left out: " +
            html_escape(text_of(views["first_unlabelled_reason"])) + ")</span>";
  fact(html, "views labelled", seen);
  const Json& slam = r["slam"];
  fact(html, "loop closures",
       text_of(slam["loop_closures_accepted"]) + " accepted of " +
           text_of(slam["loop_candidates"]) + " candidates, " +
           text_of(slam["loop_closures_pruned"]) + " pruned; pose graph " +
           (slam["pose_graph_converged"].get<bool>() ? "converged" : "did not converge"));
  if (slam.contains("degenerate_frames")) {
    std::string tracking = text_of(slam["degenerate_frames"]) + " degenerate views";
    if (slam["degenerate_frames_unmeasured"] != 0)
      tracking += " <span class=\"note\">(" + text_of(slam["degenerate_frames_unmeasured"]) +
                  " with no image or feature to measure what their geometry leaves free" +
                  poses_text(slam, "degenerate_unmeasured_poses") +
                  ": there the trajectory is the motion model's)</span>";
    tracking +=
        ", " + text_of(slam["fallback_frames"]) + " fallbacks" + poses_text(slam, "fallback_poses");
    if (slam.value("frames_from_motion_prior", 0) > 0)
      tracking += ", " + text_of(slam["frames_from_motion_prior"]) +
                  " steps predicted by the motion prior (the steps taken differ from its by "
                  "median " +
                  format_length(slam["motion_prior_difference_median_m"].get<double>()) +
                  ", at most " +
                  format_length(slam["motion_prior_difference_max_m"].get<double>()) + ")";
    if (slam.contains("motion_prior_clock"))
      tracking +=
          "; the prior's clock: " + html_escape(text_of(slam["motion_prior_clock"]["text"]));
    fact(html, "tracking", tracking);
  }
}

std::string headline(const MapReportInput& in) {
  const Json& r = in.report;
  std::string text = text_of(r["frames"]) + " frames mapped in " +
                     format_number(r["timing_s"]["total"].get<double>(), "%.1f") + " s on " +
                     html_escape(text_of(r["backend"])) + ": " + text_of(r["rooms"]["count"]) +
                     " room(s), " + text_of(r["planes"]["count"]) + " planes, " +
                     text_of(r["slam"]["map_points"]) + " map points";
  if (const Json* ate = report_member(r, {"evaluation", "trajectory", "ate_rmse_m"}))
    text += "; trajectory error (ATE RMSE) " + format_length(ate->get<double>());
  return text + ".";
}

}  // namespace

std::string report_summary_section(const MapReportInput& input) {
  std::ostringstream html;
  html << "<section id=\"summary\">\n<p class=\"headline\">" << headline(input) << "</p>\n"
       << "<table class=\"facts\">\n";
  input_facts(html, input.report);
  result_facts(html, input.report);
  html << "</table>\n</section>\n";
  return html.str();
}

}  // namespace kartograf::io::detail
