// `kartograf semantic INPUT --out DIR [--goto door|wall]`: the metric-semantic map
// (docs/methods.md M2) of one organized scan (PCD) or of an RGB-D sequence folder with camera poses
// (its ground truth, or --trajectory, e.g. a SLAM run's trajectory.txt): per-pixel labels and the
// normals image (of the scan, or of a sequence's first labelled frame), the hybrid grid
// (semantic.png with a legend, semantic.json), a ROS costmap and occupancy map, and a path to the
// nearest door or along the nearest wall from the sensor. Wiring only: the method lives in
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

#include "backend_option.hpp"
#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/range_image.hpp"
#include "kartograf/outputs/semantic_map_io.hpp"
#include "kartograf/pipeline/labelled_view_pool.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/semantic/labelled_views.hpp"
#include "kartograf/semantic/normals_image.hpp"
#include "kartograf/semantic/object_detector.hpp"
#include "kartograf/semantic/planning.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "option_checks.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

namespace {

namespace fs = std::filesystem;

constexpr double kMaxStartDistance = 3.0;  // [m]

constexpr std::initializer_list<const char*> kOutputs = {
    "labels.png",    "labels_color.png", "normals.png",   "semantic.png",
    "semantic.json", "costmap.yaml",     "occupancy.yaml"};

// Labelled points in a frame whose +z is up (the grid's), where the sensor stood, and the labels
// and normals of one view for the pictures.
struct LabelledPoints {
  semantic::LabelledViews pooled;
  std::vector<std::vector<Eigen::Vector3d>> detections;  // the points of each detected object
  Eigen::Vector3d sensor = Eigen::Vector3d::Zero();
  semantic::SemanticLabelling view;
  PointImage view_points;  // the points of `view`, in its sensor frame
};

// Turns every point (and the sensor) so that the views' up becomes +z.
void make_up_z(LabelledPoints& out) {
  const Eigen::Matrix3d rotation = out.pooled.make_up_z();
  for (std::vector<Eigen::Vector3d>& object : out.detections)
    for (Eigen::Vector3d& p : object) p = rotation * p;
  out.sensor = rotation * out.sensor;
}

// What every view goes through: the backend, and the object detector (--detect) if any.
struct Views {
  const compute::Context& context;
  std::optional<semantic::ObjectDetector> detector;
};

// What a pooled view of points seen from `pose` adds beyond its points and its up vote: its
// detections (--detect); the first view is the one pictured and the sensor's place.
void note_view(const PointImage& points, semantic::SemanticLabelling labelling,
               const Eigen::Isometry3d& pose, const Views& views, LabelledPoints& out) {
  if (views.detector) {
    for (semantic::ViewDetection& d : views.detector->detect(views.context, points)) {
      for (Eigen::Vector3d& p : d.points) p = pose * p;
      out.detections.push_back(std::move(d.points));
    }
  }
  if (out.pooled.views() == 1) {
    out.sensor = pose.translation();
    out.view = std::move(labelling);
    out.view_points = points;
  }
}

// An unorganized map (a fused SLAM map, merged scans): labelled on spherical range images from
// every --step-th camera position of --trajectory, or from one viewpoint (--viewpoint, else the
// file's own, else the centroid). A camera's range image stands upright in the camera's frame
// (image up = -y); others in the map's (up = +z).
LabelledPoints map_points(const SemanticOptions& o, const Views& views, const PointCloud& cloud,
                          std::optional<Eigen::Isometry3d> file_viewpoint, std::ostream& err) {
  require(!cloud.empty(), "semantic: '" + o.input.string() + "' holds no point");
  std::vector<Eigen::Isometry3d> viewpoints;
  if (!o.trajectory.empty()) {
    const Trajectory trajectory = io::read_tum_trajectory(o.trajectory);
    Eigen::Matrix3d sensor_axes;  // in the camera frame: x ahead = camera z, y left = -x, up = -y
    sensor_axes << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    for (std::size_t i = 0; i < trajectory.size(); i += static_cast<std::size_t>(o.step)) {
      Eigen::Isometry3d sensor = trajectory[i].pose;
      sensor.linear() = trajectory[i].pose.linear() * sensor_axes;
      viewpoints.push_back(sensor);
    }
    require(!viewpoints.empty(), "semantic: '" + o.trajectory.string() + "' holds no pose");
  } else {
    Eigen::Isometry3d sensor = Eigen::Isometry3d::Identity();
    if (!o.viewpoint.empty()) {
      require(o.viewpoint.size() == 3, "semantic: --viewpoint takes x y z");
      sensor.translation() = Eigen::Vector3d(o.viewpoint[0], o.viewpoint[1], o.viewpoint[2]);
    } else if (file_viewpoint) {
      sensor.translation() = file_viewpoint->translation();
    } else {
      for (const Eigen::Vector3f& p : cloud.points) sensor.translation() += p.cast<double>();
      sensor.translation() /= static_cast<double>(cloud.size());
    }
    viewpoints.push_back(sensor);
  }
  geometry::RangeImageParams range_params;
  range_params.angular_step_deg = o.angular_step;
  LabelledPoints out;
  for (const Eigen::Isometry3d& viewpoint : viewpoints) {
    const geometry::RangeImage image =
        geometry::make_range_image(cloud.points, viewpoint, range_params);
    std::optional<semantic::SemanticLabelling> labelling =
        pipeline::label_and_pool_view(views.context, image.points, viewpoint, {}, out.pooled);
    if (labelling) note_view(image.points, std::move(*labelling), viewpoint, views, out);
  }
  require(out.pooled.views() > 0, "semantic: no view of '" + o.input.string() +
                                      "' could be labelled: " + out.pooled.first_skip_reason());
  if (out.pooled.skipped() > 0)
    err << "semantic: " << out.pooled.skipped()
        << " viewpoints left out, e.g.: " << out.pooled.first_skip_reason() << "\n";
  make_up_z(out);
  return out;
}

// A PCD or PLY file: an organized scan is labelled on its own pixel grid, anything else as a map
// (a PCD's VIEWPOINT is where its sensor stood).
LabelledPoints scan_points(const SemanticOptions& o, const Views& views, std::ostream& err) {
  if (o.input.extension() == ".ply")
    return map_points(o, views, io::read_ply(o.input), std::nullopt, err);
  const io::PcdCloud cloud = io::read_pcd(o.input);
  if (!cloud.organized()) return map_points(o, views, cloud.to_point_cloud(), cloud.viewpoint, err);
  const PointImage points = cloud.to_point_image();
  LabelledPoints out;
  semantic::SemanticLabelling labelling;
  try {
    labelling = semantic::label_organized_points(views.context, points);
  } catch (const Error& e) {
    throw Error("semantic: '" + o.input.string() + "': " + e.what());
  }
  out.pooled.add(points, labelling.semantic, labelling.gravity, Eigen::Isometry3d::Identity());
  note_view(points, std::move(labelling), Eigen::Isometry3d::Identity(), views, out);
  make_up_z(out);
  return out;
}

// Every --step-th frame with a pose; up is the area-weighted mean of the views' estimated up
// directions in the world frame (views that see no floor or ceiling cannot say and are left out).
LabelledPoints sequence_points(const SemanticOptions& o, const Views& views, std::ostream& err) {
  SequenceInputOptions reading = o.sequence;
  reading.frames = o.frames;
  const io::OpenedSequence opened = open_input(o.input, reading, err);
  const io::Sequence& sequence = *opened.sequence;
  const std::size_t count = sequence.size();
  std::optional<Trajectory> trajectory;
  if (!o.trajectory.empty()) {
    trajectory = io::read_tum_trajectory(o.trajectory);
    // One pose per frame, in order: a shorter file would leave frames without a place.
    require(trajectory->size() >= count,
            "semantic: --trajectory '" + o.trajectory.string() + "' holds " +
                std::to_string(trajectory->size()) + " poses, the sequence '" + o.input.string() +
                "' has " + std::to_string(count) + " frames (one pose per frame, in order)");
  }
  semantic::LabellingParams params;
  params.gravity.prior_up = Eigen::Vector3d(0, -1, 0);  // a camera looking ahead: image up
  geometry::DepthRange range;
  range.units_per_metre = sequence.depth_units_per_metre();
  LabelledPoints out;
  for (std::size_t i = 0; i < count; i += static_cast<std::size_t>(o.step)) {
    const io::RgbdFrame frame = sequence.frame(i);
    std::optional<Eigen::Isometry3d> pose = frame.pose;
    if (trajectory) pose = (*trajectory)[i].pose;
    if (!pose) continue;
    const PointImage points =
        geometry::backproject(views.context, frame.depth, sequence.intrinsics(), range);
    std::optional<semantic::SemanticLabelling> labelling =
        pipeline::label_and_pool_view(views.context, points, *pose, params, out.pooled);
    if (labelling) note_view(points, std::move(*labelling), *pose, views, out);
  }
  const std::string& failure = out.pooled.first_skip_reason();
  require(out.pooled.views() > 0, "semantic: no frame of '" + o.input.string() +
                                      "' could be labelled" +
                                      (failure.empty() ? " (none has a pose)" : ": " + failure));
  if (out.pooled.skipped() > 0)
    err << "semantic: " << out.pooled.skipped() << " frames left out, e.g.: " << failure << "\n";
  make_up_z(out);
  return out;
}

// One map object per detected thing: detections (of several views) whose centres lie within
// kSameObjectDistance of each other are one object seen again; their points are pooled.
constexpr double kSameObjectDistance = 1.0;  // [m]

std::vector<semantic::ObjectDetection> place_detections(const LabelledPoints& labelled,
                                                        const std::string& object_class,
                                                        std::ostream& err) {
  std::vector<std::vector<Eigen::Vector3d>> objects;
  std::vector<Eigen::Vector2d> centres;
  for (const std::vector<Eigen::Vector3d>& points : labelled.detections) {
    if (points.size() < 3) continue;
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector3d& p : points) centre += p.head<2>();
    centre /= static_cast<double>(points.size());
    std::size_t k = 0;
    while (k < centres.size() && (centres[k] - centre).norm() > kSameObjectDistance) ++k;
    if (k == centres.size()) {
      centres.push_back(centre);
      objects.emplace_back();
    }
    objects[k].insert(objects[k].end(), points.begin(), points.end());
  }
  std::vector<semantic::ObjectDetection> out;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    try {
      out.push_back(semantic::to_map_detection(objects[k], SemanticClass::furniture,
                                               object_class + " " + std::to_string(k + 1)));
    } catch (const Error& e) {
      err << "semantic: " << e.what() << ": left off the map\n";  // seen edge-on
    }
  }
  return out;
}

// Whether the image's first rows see lower things than its last rows (a scanner whose scan lines
// start at its own height): its pictures are then turned upside down, so up is up.
bool rows_run_upwards(const PointImage& points, const Eigen::Vector3d& up) {
  const int third = points.height() / 3;
  double low_sum = 0, high_sum = 0;
  int low_count = 0, high_count = 0;
  for (int y = 0; y < points.height(); ++y) {
    if (y >= third && y < points.height() - third) continue;
    for (int x = 0; x < points.width(); ++x) {
      const Point4f& p = points(x, y);
      if (!is_valid(p)) continue;
      const double height = p.head<3>().cast<double>().dot(up);
      (y < third ? low_sum : high_sum) += height;
      ++(y < third ? low_count : high_count);
    }
  }
  return low_count > 0 && high_count > 0 && low_sum / low_count < high_sum / high_count;
}

// Colours of a view's classes; the grid's legend colours (walls black, unknown red: obstacles on a
// map) would make a picture of clutter look like an alarm.
Rgb8 view_colour(SemanticClass c) {
  switch (c) {
    case SemanticClass::floor:
      return {90, 175, 90};
    case SemanticClass::wall:
      return {205, 205, 205};
    case SemanticClass::ceiling:
      return {95, 145, 235};
    case SemanticClass::door:
      return {240, 140, 20};
    case SemanticClass::furniture:
      return {150, 80, 180};
    case SemanticClass::unknown:
      break;
  }
  return {130, 95, 75};
}

// A picture of a view for people: class colours (view_colour) shaded by how squarely each surface
// faces the sensor (black: no point), or the normals; rows turned so up is up.
RgbImage view_picture(const PointImage& points, const semantic::SemanticLabelling& labelling,
                      bool normals_only) {
  const RgbImage normals =
      semantic::normals_to_rgb(labelling.normals, semantic::NormalEncoding::absolute);
  const int w = points.width(), h = points.height();
  const bool flip = rows_run_upwards(points, labelling.gravity.up);
  RgbImage picture(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      Rgb8 colour = normals(x, y);
      if (!normals_only) {
        const Point4f& p = points(x, y);
        const Point4f& n = labelling.normals(x, y);
        double shade = 1.0;
        if (is_valid(p) && is_valid(n) && p.head<3>().norm() > 0) {
          shade = 0.55 + 0.45 * std::fabs(n.head<3>().dot(p.head<3>().normalized()));
        }
        const Rgb8 c = is_valid(p) ? view_colour(labelling.semantic(x, y)) : Rgb8{};
        for (std::size_t k = 0; k < 3; ++k) colour[k] = static_cast<std::uint8_t>(c[k] * shade);
      }
      picture(x, flip ? h - 1 - y : y) = colour;
    }
  }
  return picture;
}

}  // namespace

CLI::App* add_semantic_command(CLI::App& app, SemanticOptions& o) {
  CLI::App* command = app.add_subcommand(
      "semantic",
      "Metric-semantic grid map of an organized scan or an RGB-D sequence: floor, walls, "
      "ceiling, doors, traversability, and a path (docs/methods.md M2)");
  command
      ->add_option("INPUT", o.input,
                   "Organized PCD (a 3-D laser scan or a depth frame), an unorganized map (PCD "
                   "or PLY: labelled on range images), or an RGB-D sequence folder with poses "
                   "(TUM, 7-Scenes, kartograf synth)")
      ->required();
  command->add_option("--trajectory", o.trajectory,
                      "Sequence: camera poses in TUM format, one per frame (e.g. a SLAM run's "
                      "trajectory.txt; default: the ground truth). Map: every --step-th pose "
                      "is a viewpoint of a range image");
  command
      ->add_option("--viewpoint", o.viewpoint,
                   "Map without --trajectory: where the range image is seen from, x y z "
                   "(default: a PCD's VIEWPOINT, a PLY's centroid)")
      ->expected(3)
      ->check(finite_number());
  // 0.1 degrees is 3600 x 1500 pixels, finer than a map's samples seen from a few metres.
  command->add_option("--angular-step", o.angular_step, "Map: range image degrees per pixel")
      ->check(finite_in(0.1, 10.0))
      ->capture_default_str();
  command->add_option("--frames", o.frames, "Sequence: only the first N frames (0: all)")
      ->check(whole_number(kMaxFrames));
  add_sequence_input_options(*command, o.sequence, false, true);
  command->add_option("--step", o.step, "Sequence: every k-th frame (map: k-th viewpoint)")
      ->capture_default_str();
  command->add_option("--out", o.out_dir, "Output folder")->required();
  command->add_option("--goto", o.goto_target, "Plan from the sensor: door | wall")
      ->check(CLI::IsMember({"door", "wall"}));
  command->add_option("--resolution", o.resolution, "Grid cell size [m]")
      ->check(finite_in(0.005, 10.0))
      ->capture_default_str();
  command
      ->add_option("--detect", o.detect,
                   "Run the shipped Haar cascade of this class on every view; its finds are "
                   "objects on the grid (obstacles)")
      ->check(CLI::IsMember({"stairs"}));
  add_backend_option(*command, o.backend, o.backend_source, "Where the normals run: ");
  command->add_flag("--force", o.force, "Replace the folder of an earlier run as a whole");
  return command;
}

int run_semantic_command(const SemanticOptions& o, std::ostream& out, std::ostream& err) {
  require(std::isfinite(o.resolution) && o.resolution > 0,
          "semantic: --resolution must be > 0 m, got " + std::to_string(o.resolution));
  require(o.step >= 1, "semantic: --step must be >= 1");
  warn_untuned_grid_resolution("semantic", o.resolution, err);
  require(fs::exists(o.input), "semantic: " + o.input.string() + ": no such file or folder");
  OutputFolder folder("semantic", o.out_dir, o.force, {kOutputs.begin(), kOutputs.end()});
  const compute::Context context = backend_context(o.backend, o.backend_source);
  Views views{context, std::nullopt};
  if (o.detect == "stairs") views.detector = semantic::ObjectDetector::stairs();
  const LabelledPoints labelled =
      fs::is_directory(o.input) ? sequence_points(o, views, err) : scan_points(o, views, err);
  const std::vector<semantic::ObjectDetection> detections =
      place_detections(labelled, o.detect, err);
  const semantic::SemanticLabelling& labelling = labelled.view;
  semantic::SemanticGridParams grid_options;
  grid_options.resolution = o.resolution;
  const semantic::SemanticGrid grid = semantic::build_semantic_grid(
      labelled.pooled.points(), labelled.pooled.labels(), grid_options, detections);

  // Everything is computed (and the path planned) before the first file is written.
  semantic::MapPicture picture = semantic::render_map(grid);
  std::vector<io::NamedPath> paths;
  // A scanner does not see the floor beneath itself: plan from the nearest passable cell.
  Eigen::Vector2d sensor = labelled.sensor.head<2>();
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

  const InterruptsDeferred writing;  // a signal waits for the files, then drops them
  const fs::path& dir = folder.dir();
  io::write_semantic_png(dir / "labels.png", labelling.semantic);
  io::write_png(dir / "labels_color.png", view_picture(labelled.view_points, labelling, false));
  io::write_png(dir / "normals.png", view_picture(labelled.view_points, labelling, true));
  io::write_png(dir / "semantic.png", picture.image);
  const OccupancyGrid occupancy = semantic::to_occupancy_grid(grid);
  io::write_ros_map(dir / "occupancy.yaml", occupancy);
  io::write_ros_costmap(dir / "costmap.yaml", semantic::to_costmap(grid), grid.resolution,
                        occupancy.origin);
  io::write_semantic_json(dir / "semantic.json", grid, paths, o.input.string());
  folder.commit();

  std::map<std::string, int> kinds;
  for (const semantic::SemanticObject& object : grid.objects)
    ++kinds[std::string(semantic::to_string(object.kind))];
  out << o.input.string() << ": " << labelled.pooled.views() << " view(s), " << grid.width() << "x"
      << grid.height() << " cells of " << grid.resolution << " m;";
  for (const auto& [kind, count] : kinds) out << " " << count << " " << kind;
  for (const io::NamedPath& p : paths)
    out << "; " << p.query << ": " << p.path.length << " m to object " << p.path.target_object;
  out << " -> " << o.out_dir.string() << "\n";
  return 0;
}

}  // namespace kartograf::cli
