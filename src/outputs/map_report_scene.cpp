// report.html: the 3-D view. The data sit in the page as JSON: a subsample of the map's points
// (positions quantised to 16 bits per axis within their bounds, colours as bytes, both base64),
// the estimated and the true camera paths; report/map_viewer.js draws them with three.js.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "outputs/html_text.hpp"
#include "outputs/map_report_html.hpp"
#include "outputs/report_assets.hpp"
#include "kartograf/formats/top_view.hpp"

namespace kartograf::io::detail {

namespace {

constexpr double kMapVoxelM = 0.02;  // the fused map's point spacing (docs/user-guide.md)

// Every (n / count)-th point: a subsample that keeps the map's spread.
std::vector<std::size_t> subsample(std::size_t n, std::size_t count) {
  std::vector<std::size_t> picked(std::min(n, count));
  for (std::size_t k = 0; k < picked.size(); ++k) picked[k] = k * n / picked.size();
  return picked;
}

Json points_json(const PointCloud& map, const std::vector<std::size_t>& picked) {
  Eigen::Vector3f low = Eigen::Vector3f::Constant(0), high = Eigen::Vector3f::Constant(1);
  if (!picked.empty()) low = high = map.points[picked.front()];
  for (const std::size_t i : picked) {
    low = low.cwiseMin(map.points[i]);
    high = high.cwiseMax(map.points[i]);
  }
  const Eigen::Vector3f extent = (high - low).cwiseMax(Eigen::Vector3f::Constant(1e-6f));
  std::vector<std::uint8_t> positions, colours;
  positions.reserve(picked.size() * 6);
  for (const std::size_t i : picked) {
    for (int a = 0; a < 3; ++a) {  // little-endian, as JavaScript's typed arrays read it
      const auto q = static_cast<std::uint16_t>(
          std::lround(std::clamp((map.points[i][a] - low[a]) / extent[a], 0.0f, 1.0f) * 65535));
      positions.push_back(static_cast<std::uint8_t>(q & 0xff));
      positions.push_back(static_cast<std::uint8_t>(q >> 8));
    }
    if (map.has_colors()) colours.insert(colours.end(), map.colors[i].begin(), map.colors[i].end());
  }
  const double sparsity = picked.empty() ? 1.0 : static_cast<double>(map.size()) / picked.size();
  return {{"count", picked.size()},
          {"total", map.size()},
          {"min", {low.x(), low.y(), low.z()}},
          {"max", {low.x() + extent.x(), low.y() + extent.y(), low.z() + extent.z()}},
          {"positions", base64(positions)},
          {"colours", base64(colours)},
          {"point_size", std::clamp(kMapVoxelM * std::sqrt(sparsity), 0.02, 0.08)}};
}

// x, y, z, x, y, z, ... rounded to millimetres.
Json path_json(const std::vector<Eigen::Vector3d>& path) {
  Json coordinates = Json::array();
  for (const Eigen::Vector3d& p : path)
    for (int a = 0; a < 3; ++a) coordinates.push_back(std::round(p[a] * 1000) / 1000);
  return coordinates;
}

Json scene_json(const MapReportInput& in, std::size_t max_points) {
  const std::vector<std::size_t> picked = subsample(in.result.map.size(), max_points);
  Json scene = points_json(in.result.map, picked);
  std::vector<Eigen::Vector3d> estimated, truth;
  double camera_top = 0;
  for (const Eigen::Isometry3d& pose : in.result.poses) {
    estimated.push_back(pose.translation());
    camera_top = std::max(camera_top, pose.translation().z());
  }
  if (in.evaluation)
    for (const pipeline::FrameTrajectoryError& f : in.evaluation->frame_errors)
      truth.push_back(f.true_position_in_map);
  scene["estimated"] = path_json(estimated);
  scene["truth"] = path_json(truth);
  // Points above this are the ceiling (the top view's rule): hidden until asked for.
  scene["ceiling_z"] = camera_top + TopViewParams{}.ceiling_clearance;
  return scene;
}

}  // namespace

std::string report_scene_section(const MapReportInput& input, std::size_t max_points) {
  const Json scene = scene_json(input, max_points);
  std::ostringstream html;
  html << "<section id=\"view3d\">\n<h2>3-D view</h2>\n<p class=\"note\">" << scene["count"].dump()
       << " of the map's " << scene["total"].dump() << " points; drag to turn, right-drag or "
       << "shift-drag to move, wheel to zoom.</p>\n"
       << "<div class=\"viewer\"><canvas id=\"map-3d-canvas\"></canvas>\n"
       << "<div class=\"viewer-tools\"><button type=\"button\" "
          "data-view=\"oblique\">oblique</button>"
       << "<button type=\"button\" data-view=\"above\">from above</button>"
       << "<label><input type=\"checkbox\" id=\"map-3d-ceiling\"> ceiling</label>"
       << "<span class=\"key\"><i class=\"estimated\"></i>estimated path";
  if (!scene["truth"].empty()) html << " <i class=\"truth\"></i>true path";
  html << "</span></div>\n<p class=\"viewer-message\" id=\"map-3d-message\" hidden></p></div>\n"
       << "<script type=\"application/json\" id=\"map-3d-data\">" << inline_script(scene.dump())
       << "</script>\n</section>\n";
  return html.str();
}

std::string report_scene_scripts() {
  std::string html;
  for (const std::string_view script : {three_js(), orbit_controls_js(), map_viewer_js()})
    html.append("<script>").append(inline_script(script)).append("</script>\n");
  return html;
}

}  // namespace kartograf::io::detail
