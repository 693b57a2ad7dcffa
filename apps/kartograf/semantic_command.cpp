// `kartograf semantic SCAN --out DIR [--goto door|wall]`: the metric-semantic map of one organized
// scan (methods.md M2): per-pixel labels (labels.png), the normals image (normals.png), the hybrid
// grid (semantic.png with a legend, semantic.json), a ROS costmap and occupancy map, and a path to
// the nearest door or along the nearest wall from the sensor. Wiring only: the method lives in
// semantic/, the files in io/.
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>

#include "commands.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/io/image_io.hpp"
#include "kartograf/io/occupancy_map_io.hpp"
#include "kartograf/io/pcd.hpp"
#include "kartograf/io/semantic_map_io.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/semantic/normals_image.hpp"
#include "kartograf/semantic/planning.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "output_folder.hpp"

namespace kartograf::cli {

namespace {

namespace fs = std::filesystem;

constexpr double kMaxStartDistance = 3.0;  // [m]

constexpr std::initializer_list<const char*> kOutputs = {
    "labels.png",    "labels_color.png", "normals.png",   "semantic.png",
    "semantic.json", "costmap.yaml",     "occupancy.yaml"};

// The labelled points turned so that the estimated gravity's up is +z (the grid's frame).
struct GravityAlignedPoints {
  std::vector<Eigen::Vector3d> points;
  std::vector<SemanticClass> labels;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // sensor frame -> grid frame
};

GravityAlignedPoints align_to_gravity(const PointImage& points,
                                      const semantic::SemanticLabelling& labelling) {
  GravityAlignedPoints aligned;
  aligned.rotation =
      Eigen::Quaterniond::FromTwoVectors(labelling.gravity.up, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point4f& p = points.data()[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) continue;
    aligned.points.push_back(aligned.rotation * p.head<3>().cast<double>());
    aligned.labels.push_back(labelling.semantic.data()[i]);
  }
  return aligned;
}

// The class colours of the grid picture's legend, per pixel (black: no point).
RgbImage colour_labels(const SemanticImage& labels) {
  RgbImage picture(labels.width(), labels.height());
  for (std::size_t i = 0; i < labels.size(); ++i)
    picture.data()[i] = semantic::class_colour(labels.data()[i]);
  return picture;
}

}  // namespace

CLI::App* add_semantic_command(CLI::App& app, SemanticOptions& o) {
  CLI::App* command = app.add_subcommand(
      "semantic",
      "Metric-semantic grid map of an organized scan (PCD): floor, walls, ceiling, doors, "
      "traversability, and a path (methods.md M2)");
  command->add_option("SCAN", o.input, "Organized PCD: a 3-D laser scan or a depth camera frame")
      ->required();
  command->add_option("--out", o.out_dir, "Output folder")->required();
  command->add_option("--goto", o.goto_target, "Plan from the sensor: door | wall")
      ->check(CLI::IsMember({"door", "wall"}));
  command->add_option("--resolution", o.resolution, "Grid cell size [m]")->capture_default_str();
  if (const char* env_backend = std::getenv("KARTOGRAF_BACKEND"); env_backend && *env_backend) {
    o.backend = env_backend;
    o.backend_source = "KARTOGRAF_BACKEND";
  }
  command
      ->add_option("--backend", o.backend,
                   "Where the normals run: auto|cpu|vulkan|opencl (default: $KARTOGRAF_BACKEND, "
                   "else auto)")
      ->each([&o](const std::string&) { o.backend_source = "--backend"; });
  command->add_flag("--force", o.force, "Overwrite the files of an earlier run");
  return command;
}

int run_semantic_command(const SemanticOptions& o, std::ostream& out) {
  require(std::isfinite(o.resolution) && o.resolution > 0,
          "semantic: --resolution must be > 0 m, got " + std::to_string(o.resolution));
  check_output_folder("semantic", o.out_dir, kOutputs, o.force);
  const io::PcdCloud cloud = io::read_pcd(o.input);
  require(cloud.organized(), "semantic: '" + o.input.string() +
                                 "' is not organized (height 1): the labelling needs the "
                                 "scan's pixel grid");
  const PointImage points = cloud.to_point_image();

  compute::ContextOptions context_options;
  context_options.backend = compute::parse_backend_choice(o.backend, o.backend_source);
  const compute::Context context(context_options);
  const semantic::SemanticLabelling labelling = semantic::label_organized_points(context, points);
  const GravityAlignedPoints aligned = align_to_gravity(points, labelling);
  semantic::SemanticGridOptions grid_options;
  grid_options.resolution = o.resolution;
  const semantic::SemanticGrid grid =
      semantic::build_semantic_grid(aligned.points, aligned.labels, grid_options);

  // Everything is computed (and the path planned) before the first file is written.
  semantic::MapPicture picture = semantic::render_map(grid);
  std::vector<io::NamedPath> paths;
  // A scanner does not see the floor beneath itself: plan from the nearest passable cell.
  Eigen::Vector2d sensor = Eigen::Vector2d::Zero();
  if (!o.goto_target.empty()) {
    const std::optional<Eigen::Vector2d> start =
        semantic::nearest_passable_point(grid, sensor, kMaxStartDistance);
    require(start.has_value(), "semantic: no passable cell within " +
                                   std::to_string(kMaxStartDistance) +
                                   " m of the sensor to start the path from");
    sensor = *start;
  }
  if (o.goto_target == "door")
    paths.push_back({"goto door", semantic::plan_to_nearest_door(grid, sensor)});
  if (o.goto_target == "wall")
    paths.push_back({"along wall", semantic::plan_along_nearest_wall(grid, sensor)});
  for (const io::NamedPath& p : paths) semantic::draw_path(picture, p.path);

  fs::create_directories(o.out_dir);
  io::write_semantic_png(o.out_dir / "labels.png", labelling.semantic);
  io::write_png(o.out_dir / "labels_color.png", colour_labels(labelling.semantic));
  io::write_png(o.out_dir / "normals.png",
                semantic::normals_to_rgb(labelling.normals, semantic::NormalEncoding::absolute));
  io::write_png(o.out_dir / "semantic.png", picture.image);
  const OccupancyGrid occupancy = semantic::to_occupancy_grid(grid);
  io::write_ros_map(o.out_dir / "occupancy.yaml", occupancy);
  io::write_ros_costmap(o.out_dir / "costmap.yaml", semantic::to_costmap(grid), grid.resolution,
                        occupancy.origin);
  io::write_semantic_json(o.out_dir / "semantic.json", grid, paths, o.input.string());

  std::map<std::string, int> kinds;
  for (const semantic::SemanticObject& object : grid.objects)
    ++kinds[std::string(semantic::to_string(object.kind))];
  out << o.input.string() << ": " << grid.width() << "x" << grid.height() << " cells of "
      << grid.resolution << " m;";
  for (const auto& [kind, count] : kinds) out << " " << count << " " << kind;
  for (const io::NamedPath& p : paths)
    out << "; " << p.query << ": " << p.path.length << " m to object " << p.path.target_object;
  out << " -> " << o.out_dir.string() << "\n";
  return 0;
}

}  // namespace kartograf::cli
