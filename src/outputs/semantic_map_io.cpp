#include "kartograf/outputs/semantic_map_io.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "outputs/json_array.hpp"

namespace kartograf::io {

namespace {

using Json = nlohmann::ordered_json;
using detail::json_array;

Json polyline(const std::vector<Eigen::Vector2d>& points) {
  Json list = Json::array();
  for (const Eigen::Vector2d& p : points) list.push_back(json_array(p));
  return list;
}

// NaN (unknown) as null: JSON has no NaN.
Json weight_json(float weight) {
  return std::isnan(weight) ? Json() : Json(weight);
}

Json object_json(const semantic::ObjectRecord& o) {
  return {{"id", o.id},
          {"kind", o.kind},
          {"label", o.label},
          {"name", o.name},
          {"centre", json_array(o.centre)},
          {"width_m", o.width},
          {"area_m2", o.area},
          {"z_min", o.z_min},
          {"z_max", o.z_max},
          {"axis", {json_array(o.axis_start), json_array(o.axis_end)}},
          {"cells", o.cell_count},
          {"contour", polyline(o.contour)}};
}

}  // namespace

void write_semantic_json(const std::filesystem::path& path, const semantic::SemanticGrid& grid,
                         std::span<const NamedPath> paths, const std::string& source) {
  const semantic::MapDescription d = semantic::describe(grid);
  Json json;
  json["format"] = "kartograf-semantic-grid";
  json["version"] = 1;
  json["source"] = source;
  json["resolution"] = d.resolution;
  json["origin"] = json_array(d.origin);
  json["width"] = d.width;
  json["height"] = d.height;
  json["floor_z"] = d.floor_z;
  json["ceiling_z"] = d.ceiling_z ? Json(*d.ceiling_z) : Json();
  Json weights = Json::object();
  for (const auto& [name, weight] : d.class_weights) weights[name] = weight_json(weight);
  json["traversability"] = std::move(weights);
  Json cells = Json::object();
  for (int c = 0; c < kSemanticClassCount; ++c)
    cells[std::string(to_string(static_cast<SemanticClass>(c)))] = d.cells_per_class[c];
  cells["unobserved"] = d.unobserved_cells;
  json["cells"] = std::move(cells);
  json["inferred"] = {
      {"wall_thickness_m", d.inferred.wall_thickness ? Json(*d.inferred.wall_thickness) : Json()},
      {"lattice_offset_m", json_array(d.inferred.lattice_offset)},
      {"wall_face_crispness", json_array(d.inferred.wall_face_crispness)},
      {"furniture_fronts", d.inferred.furniture_fronts},
      {"furniture_pockets", d.inferred.furniture_pockets},
      {"wall_specks", d.inferred.wall_specks},
      {"furniture_in_wall_lines", d.inferred.furniture_in_wall_lines},
      {"wall_insides_behind_fronts", d.inferred.wall_insides_behind_fronts},
      {"wall_corners_behind_furniture", d.inferred.wall_corners_behind_furniture},
      {"wall_cells_across_unseen", d.inferred.wall_cells_across_unseen},
      {"tables_on_legs", d.inferred.tables_on_legs},
      {"fill_cells_trimmed_at_tables", d.inferred.fill_cells_trimmed_at_tables},
      {"lone_posts_kept", d.inferred.lone_posts_kept},
      {"floor_seen_through", d.inferred.floor_seen_through}};
  Json objects = Json::array();
  for (const semantic::ObjectRecord& o : d.objects) objects.push_back(object_json(o));
  json["objects"] = std::move(objects);
  Json planned = Json::array();
  for (const NamedPath& p : paths) {
    planned.push_back({{"query", p.query},
                       {"target_object", p.path.target_object},
                       {"length_m", p.path.length},
                       {"cost", p.path.cost},
                       {"points", polyline(p.path.points)}});
  }
  json["paths"] = std::move(planned);
  const std::string text = json.dump(1) + "\n";
  detail::write_file_atomically(path, text.data(), text.size());
}

void write_ros_costmap(const std::filesystem::path& yaml_path, const Image<std::uint8_t>& costmap,
                       double resolution, const Eigen::Vector3d& origin) {
  const std::string name = "costmap " + yaml_path.string();
  require(!costmap.empty(), name + ": the costmap is empty");
  require(std::isfinite(resolution) && resolution > 0,
          name + ": the resolution must be > 0, got " + std::to_string(resolution));
  std::filesystem::path image_path = yaml_path;
  image_path.replace_extension(".pgm");
  require(image_path != yaml_path, name + ": the YAML file must not end in .pgm");
  std::string pgm = "P5\n# CREATOR: kartograf (costmap: 0 free .. 254 lethal, 255 unknown)\n" +
                    std::to_string(costmap.width()) + " " + std::to_string(costmap.height()) +
                    "\n255\n";
  pgm.append(reinterpret_cast<const char*>(costmap.data()), costmap.size());
  const auto number = [](double v) {
    std::ostringstream text;
    text.precision(9);
    text << v;
    return text.str();
  };
  const std::string yaml = "image: " + image_path.filename().string() +
                           "\nmode: raw\nresolution: " + number(resolution) + "\norigin: [" +
                           number(origin.x()) + ", " + number(origin.y()) + ", " +
                           number(origin.z()) +
                           "]\nnegate: 0\noccupied_thresh: 0.65\n"
                           "free_thresh: 0.196\n";
  detail::write_file_atomically(image_path, pgm.data(), pgm.size());
  detail::write_file_atomically(yaml_path, yaml.data(), yaml.size());
}

}  // namespace kartograf::io
