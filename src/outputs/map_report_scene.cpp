// report.html: the 3-D view. The data sit in the page as JSON: the map's mesh (its vertices
// clustered until at most max_triangles remain) or, without one, a subsample of its points
// (positions quantised to 16 bits per axis within their bounds, colours as bytes, triangles as
// 32-bit vertex indices, all base64), the estimated and the true camera paths;
// report/map_viewer.js draws them with three.js.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include "kartograf/core/color.hpp"
#include "kartograf/formats/top_view.hpp"
#include "outputs/html_text.hpp"
#include "outputs/map_report_html.hpp"
#include "outputs/report_assets.hpp"

namespace kartograf::io::detail {

namespace {

constexpr double kMapVoxelM = 0.02;  // the fused map's point spacing (docs/user-guide.md)

// Every (n / count)-th point: a subsample that keeps the map's spread.
std::vector<std::size_t> subsample(std::size_t n, std::size_t count) {
  std::vector<std::size_t> picked(std::min(n, count));
  for (std::size_t k = 0; k < picked.size(); ++k) picked[k] = k * n / picked.size();
  return picked;
}

// The mesh with its vertices merged per cube of side `cell` (their mean position, the first
// one's colour); triangles that lose a corner go (vertex clustering, Rossignac and Borrel 1993).
TriangleMesh cluster_vertices(const TriangleMesh& mesh, float cell) {
  std::unordered_map<std::uint64_t, std::uint32_t> cluster_of_cell;
  std::vector<std::uint32_t> cluster(mesh.vertices.size());
  std::vector<int> members;
  TriangleMesh out;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3i c = (mesh.vertices[i] / cell).array().floor().cast<int>();
    const std::uint64_t key = (static_cast<std::uint64_t>(c.x() & 0x1fffff) << 42) |
                              (static_cast<std::uint64_t>(c.y() & 0x1fffff) << 21) |
                              static_cast<std::uint64_t>(c.z() & 0x1fffff);
    const auto [at, added] =
        cluster_of_cell.try_emplace(key, static_cast<std::uint32_t>(out.vertices.size()));
    if (added) {
      out.vertices.push_back(Eigen::Vector3f::Zero());
      members.push_back(0);
      if (!mesh.colors.empty()) out.colors.push_back(mesh.colors[i]);
    }
    cluster[i] = at->second;
    out.vertices[at->second] += mesh.vertices[i];
    ++members[at->second];
  }
  for (std::size_t k = 0; k < out.vertices.size(); ++k) out.vertices[k] /= float(members[k]);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3i m(int(cluster[t[0]]), int(cluster[t[1]]), int(cluster[t[2]]));
    if (m[0] != m[1] && m[1] != m[2] && m[0] != m[2]) out.triangles.push_back(m);
  }
  return out;
}

// The mesh coarsened (cells growing by half) until it has at most max_triangles.
TriangleMesh mesh_for_view(const TriangleMesh& mesh, std::size_t max_triangles) {
  if (mesh.triangles.size() <= max_triangles) return mesh;
  Eigen::Vector3f low = mesh.vertices.front(), high = low;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    low = low.cwiseMin(v);
    high = high.cwiseMax(v);
  }
  // A first cell from the area per triangle the budget allows (a surface's triangles ~
  // area/cell^2).
  float cell = std::max(0.005f, std::sqrt(static_cast<float>(mesh.triangles.size()) /
                                          static_cast<float>(max_triangles)) *
                                    0.01f);
  TriangleMesh coarse = cluster_vertices(mesh, cell);
  while (coarse.triangles.size() > max_triangles) {
    cell *= 1.5f;
    coarse = cluster_vertices(mesh, cell);
  }
  return coarse;
}

std::string triangles_base64(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(triangles.size() * 12);
  for (const Eigen::Vector3i& t : triangles)
    for (int k = 0; k < 3; ++k)
      for (int b = 0; b < 4; ++b)  // little-endian
        bytes.push_back(
            static_cast<std::uint8_t>((static_cast<std::uint32_t>(t[k]) >> (8 * b)) & 0xff));
  return base64(bytes);
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

// The mesh's vertices as points_json's cloud, and its triangles.
Json mesh_json(const TriangleMesh& full, std::size_t max_triangles) {
  const TriangleMesh mesh = mesh_for_view(full, max_triangles);
  PointCloud cloud;
  cloud.points = mesh.vertices;
  for (const std::uint32_t c : mesh.colors) cloud.colors.push_back(unpack_rgb(c));
  std::vector<std::size_t> all(cloud.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  Json scene = points_json(cloud, all);
  scene["triangles"] = triangles_base64(mesh.triangles);
  scene["triangle_count"] = mesh.triangles.size();
  scene["total_triangles"] = full.triangles.size();
  return scene;
}

Json scene_json(const MapReportInput& in, std::size_t max_points) {
  const TriangleMesh& mesh = in.result.mesh;
  // A mesh of max_points / 2 triangles has about as many vertices as the cloud's max_points.
  Json scene = mesh.triangles.empty()
                   ? points_json(in.result.map, subsample(in.result.map.size(), max_points))
                   : mesh_json(mesh, max_points / 2);
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
  html << "<section id=\"view3d\">\n<h2>3-D view</h2>\n<p class=\"note\">";
  if (scene.contains("triangles")) {
    html << "The TSDF's mesh: " << scene["triangle_count"].dump() << " of its "
         << scene["total_triangles"].dump() << " triangles";
  } else {
    html << scene["count"].dump() << " of the map's " << scene["total"].dump() << " points";
  }
  html << "; drag to turn, right-drag or shift-drag to move, wheel to zoom.</p>\n"
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
