#pragma once
// report.html of a map run, for a person: the summary and each metric against its target first,
// then the pictures, plots of the trajectory error and the stage times, the class confusion, a
// 3-D view of the map (three.js, inlined), and every value of report.json at the end. The page
// needs nothing outside its folder (it links only the folder's own files) and no network.
//
// The page checks itself when it loads (report/report_checks.js): it sets, on <html>,
// data-images ("ok N" or the pictures that did not load), data-scene ("ok ..." once the 3-D view
// is drawn) and data-errors (every script or console error); a test reads them from the DOM.
#include <initializer_list>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "kartograf/pipeline/map_evaluation.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"

namespace kartograf::io::detail {

using Json = nlohmann::ordered_json;

struct MapReportInput {
  const Json& report;  // report.json of the run
  const pipeline::MapPipelineResult& result;
  const std::optional<pipeline::MapEvaluation>& evaluation;
  bool evaluation_picture = false;  // evaluation.png is written beside the report
};

std::string map_report_html(const MapReportInput& input);

// report[path...], or nullptr where a member is missing or null (reports of older runs).
const Json* report_member(const Json& report, std::initializer_list<const char*> path);
// A string as it is, anything else as JSON text.
std::string text_of(const Json& value);

// The sections, in the page's order (map_report_metrics.cpp, map_report_scene.cpp).
std::string report_summary_section(const MapReportInput& input);
std::string report_metrics_section(const MapReportInput& input);
std::string report_confusion_section(const Json& report);
// At most max_points of the map's points, the estimated trajectory and, where known, the true one.
std::string report_scene_section(const MapReportInput& input, std::size_t max_points = 200000);
// The scripts that build the 3-D view; they come last in the page.
std::string report_scene_scripts();

}  // namespace kartograf::io::detail
