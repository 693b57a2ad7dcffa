#include "kartograf/outputs/synthetic_dataset.hpp"

#include <atomic>
#include <cstdio>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/random.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/synth/floor_plan.hpp"
#include "kartograf/synth/preview.hpp"

namespace kartograf::io {

namespace {

using detail::quoted;
using Json = nlohmann::ordered_json;

// Salts that derive the independent seeds of a data set's parts from its seed.
constexpr std::uint64_t kFrameSalt = 0x6672616d65ULL;   // "frame"
constexpr std::uint64_t kLaserSalt = 0x6c61736572ULL;   // "laser"
constexpr std::uint64_t kHandheldSalt = 0x68616e64ULL;  // "hand"

Json to_json(const Eigen::Vector2d& v) {
  return Json::array({v.x(), v.y()});
}
Json to_json(const Eigen::Vector3d& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

Json pose_json(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  return {{"translation", to_json(Eigen::Vector3d(pose.translation()))},
          {"quaternion_xyzw", Json::array({q.x(), q.y(), q.z(), q.w()})}};
}

std::string axis_name(int axis) {
  return axis == 0 ? "x" : axis == 1 ? "y" : "z";
}

Json box_json(const synth::World& w, int solid) {
  const synth::Box3& b = w.solids[static_cast<std::size_t>(solid)].box;
  return Json{{"min", to_json(b.min)}, {"max", to_json(b.max)}};
}

Json rooms_json(const synth::World& w) {
  Json rooms = Json::array();
  for (const synth::Room& r : w.rooms) {
    rooms.push_back({{"id", r.id},
                     {"name", r.name},
                     {"kind", r.kind == synth::RoomKind::corridor ? "corridor" : "room"},
                     {"min", to_json(r.rect.min)},
                     {"max", to_json(r.rect.max)},
                     {"area", r.rect.area()},
                     {"wall_planes",
                      {{"east", r.wall_planes[0]},
                       {"west", r.wall_planes[1]},
                       {"north", r.wall_planes[2]},
                       {"south", r.wall_planes[3]}}},
                     {"wall_material", r.wall_material},
                     {"floor_material", r.floor_material}});
  }
  return rooms;
}

Json doorways_json(const synth::World& w) {
  Json doorways = Json::array();
  for (const synth::Doorway& d : w.doorways) {
    doorways.push_back({{"id", d.id},
                        {"rooms", Json::array({d.rooms[0], d.rooms[1]})},
                        {"min", to_json(d.opening.min)},
                        {"max", to_json(d.opening.max)},
                        {"width", d.width},
                        {"height", d.height},
                        {"passage_axis", axis_name(d.passage_axis)},
                        {"jamb_planes", Json::array({d.jamb_planes[0], d.jamb_planes[1]})},
                        {"soffit_plane", d.soffit_plane}});
  }
  return doorways;
}

Json door_leaves_json(const synth::World& w) {
  Json leaves = Json::array();
  for (const synth::DoorLeaf& leaf : w.door_leaves) {
    Json entry = box_json(w, leaf.solid);
    entry["doorway"] = leaf.doorway;
    entry["room"] = leaf.room;
    entry["material"] = leaf.material;
    leaves.push_back(entry);
  }
  return leaves;
}

Json furniture_json(const synth::World& w) {
  Json furniture = Json::array();
  for (const synth::Furniture& f : w.furniture) {
    Json boxes = Json::array();
    for (int solid : f.solids) boxes.push_back(box_json(w, solid));
    furniture.push_back(
        {{"id", f.id},
         {"kind", synth::to_string(f.kind)},
         {"room", f.room},
         {"footprint", {{"min", to_json(f.footprint.min)}, {"max", to_json(f.footprint.max)}}},
         {"height", f.height},
         {"material", f.material},
         {"boxes", boxes}});
  }
  return furniture;
}

Json planes_json(const synth::World& w) {
  Json planes = Json::array();
  for (const synth::Plane& p : w.planes) {
    Json polygons = Json::array();
    for (const auto& polygon : p.polygons) {
      Json vertices = Json::array();
      for (const Eigen::Vector3d& v : polygon) vertices.push_back(to_json(v));
      polygons.push_back(vertices);
    }
    planes.push_back({{"id", p.id},
                      {"class", static_cast<int>(p.semantic)},
                      {"class_name", std::string(to_string(p.semantic))},
                      {"normal", to_json(p.normal)},
                      {"offset", p.offset},
                      {"room", p.room},
                      {"material", p.material},
                      {"name", p.name},
                      {"area", p.area()},
                      {"polygons", polygons}});
  }
  return planes;
}

Json materials_json(const synth::World& w) {
  Json materials = Json::array();
  for (std::size_t i = 0; i < w.materials.size(); ++i) {
    const synth::Material& m = w.materials[i];
    materials.push_back({{"index", i},
                         {"name", m.name},
                         {"pattern", std::string(synth::to_string(m.pattern))},
                         {"color_a", to_json(m.color_a)},
                         {"color_b", to_json(m.color_b)},
                         {"period", m.period},
                         {"noise_amplitude", m.noise_amplitude},
                         {"noise_scale", m.noise_scale},
                         {"albedo", synth::luminance(m.color_a)}});
  }
  return materials;
}

Json route_json(const synth::World& w) {
  Json route = Json::array();
  for (const synth::RouteVertex& v : w.route) {
    route.push_back(
        {{"x", v.position.x()}, {"y", v.position.y()}, {"straight_margin", v.straight_margin}});
  }
  return route;
}

Json world_json(const synth::World& w) {
  Json json;
  json["format"] = "kartograf synthetic world";
  json["version"] = 1;
  json["seed"] = w.seed;
  json["frame"] = "metres; z up; floor at z = 0; plane equation normal . x + offset = 0";
  json["height"] = w.height;
  json["wall_thickness"] = w.wall_thickness;
  json["bounds"] = {{"min", to_json(w.bounds.min)}, {"max", to_json(w.bounds.max)}};
  Json classes = Json::array();
  for (std::string_view name : kSemanticClassNames) classes.push_back(std::string(name));
  json["semantic_classes"] = classes;
  json["floor_plane"] = w.floor_plane;
  json["ceiling_plane"] = w.ceiling_plane;
  json["rooms"] = rooms_json(w);
  json["doorways"] = doorways_json(w);
  json["door_leaves"] = door_leaves_json(w);
  json["furniture"] = furniture_json(w);
  json["planes"] = planes_json(w);
  json["materials"] = materials_json(w);
  json["route"] = route_json(w);
  return json;
}

Json noise_json(const synth::NoiseModel& n) {
  return {{"axial", n.axial},
          {"axial_a", n.axial_a},
          {"axial_b", n.axial_b},
          {"axial_c", n.axial_c},
          {"axial_angle_term", n.axial_angle_term},
          {"lateral", n.lateral},
          {"lateral_px", n.lateral_px},
          {"quantization", n.quantization},
          {"baseline", n.baseline},
          {"subpixel", n.subpixel},
          {"min_range", n.min_range},
          {"max_range", std::isfinite(n.max_range) ? Json(n.max_range) : Json(nullptr)},
          {"grazing_dropout", n.grazing_dropout},
          {"grazing_start_deg", n.grazing_start_deg},
          {"grazing_limit_deg", n.grazing_limit_deg},
          {"dark_dropout", n.dark_dropout},
          {"dark_albedo", n.dark_albedo},
          {"flying_pixels", n.flying_pixels},
          {"flying_fraction", n.flying_fraction},
          {"flying_min_jump", n.flying_min_jump},
          {"color_noise", n.color_noise},
          {"color_sigma", n.color_sigma}};
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  detail::write_file_atomically(path, text.data(), text.size());
}

// TUM's rgb.txt / depth.txt.
std::string frame_list(const char* what, const char* folder, const Trajectory& trajectory,
                       std::uint64_t seed) {
  std::string text = std::string("# ") + what + "\n# file: 'kartograf synth seed " +
                     std::to_string(seed) + "'\n# timestamp filename\n";
  for (const StampedPose& p : trajectory) {
    const std::string stem = timestamp_name(p.timestamp);
    text += stem + " " + folder + "/" + stem + ".png\n";
  }
  return text;
}

void prepare_folder(const std::filesystem::path& dir, bool force) {
  std::error_code error;
  if (std::filesystem::exists(dir, error)) {
    require(std::filesystem::is_directory(dir, error), quoted(dir) + " exists and is not a folder");
    require(force || std::filesystem::is_empty(dir, error),
            quoted(dir) + " is not empty: choose a new folder, or pass --force to write into it");
  }
  for (const char* sub : {"rgb", "depth", "gt/planes", "gt/semantic"}) {
    std::filesystem::create_directories(dir / sub, error);
    require(!error, "cannot create " + quoted(dir / sub) + ": " + error.message());
  }
}

Label largest_room(const synth::World& world) {
  Label best = 0;
  double area = -1;
  for (const synth::Room& r : world.rooms) {
    if (r.kind == synth::RoomKind::room && r.rect.area() > area) best = r.id, area = r.rect.area();
  }
  return best;
}

// Renders and writes the frames on `workers` threads; each frame is independent.
void write_frames(const std::filesystem::path& dir, const synth::World& world,
                  const Trajectory& trajectory, const SyntheticDatasetParams& options,
                  int workers) {
  const int count = static_cast<int>(trajectory.size());
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;  // guards error, done and progress
  std::exception_ptr error;
  int done = 0;
  auto work = [&] {
    for (int k; !failed && (k = next++) < count;) {
      try {
        const synth::SyntheticFrame frame =
            synth::render(world, options.intrinsics, trajectory[k].pose, options.noise,
                          synthetic_frame_seed(options.seed, static_cast<std::size_t>(k)), {1});
        const std::string name = timestamp_name(trajectory[k].timestamp) + ".png";
        write_png(dir / "rgb" / name, frame.color);
        write_png(dir / "depth" / name, frame.depth);
        write_label_png(dir / "gt" / "planes" / name, frame.plane_id);
        write_semantic_png(dir / "gt" / "semantic" / name, frame.semantic);
        const std::lock_guard lock(mutex);
        ++done;
        if (options.progress && (done % std::max(1, count / 10) == 0 || done == count)) {
          options.progress("frames " + std::to_string(done) + "/" + std::to_string(count));
        }
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < workers; ++i) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

void report(const SyntheticDatasetParams& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

void check_options(const SyntheticDatasetParams& options) {
  const bool robot = options.trajectory == SyntheticTrajectory::robot;
  require((options.frames >= 1 || (robot && options.frames == 0)) && options.frames <= 100000,
          "synthetic data set: frames must be in 1..100000 (0: a robot tour's own count), got " +
              std::to_string(options.frames));
  options.intrinsics.validate("synthetic data set intrinsics");
  options.noise.validate();
  options.laser.validate();
}

// The camera's path into summary.trajectory.
struct CameraPath {
  Label handheld_room = 0;  // 0: a robot tour
  int frames = 0;           // the frames rendered
};

// A robot tour of every room (frames 0: as many as the tour needs).
CameraPath plan_robot_tour(const SyntheticDatasetParams& options,
                           SyntheticDatasetSummary& summary) {
  const synth::World& world = summary.world;
  int frames = options.frames;
  summary.tour_frames_needed = synth::tour_frames_needed(world, options.tour);
  if (frames == 0) frames = summary.tour_frames_needed;
  // A tour of 1 frame is no tour: render its start.
  summary.trajectory = synth::robot_tour(world, std::max(2, frames), options.tour);
  summary.trajectory.resize(static_cast<std::size_t>(frames));
  if (summary.tour_frames_needed > frames) {
    char note[200];
    std::snprintf(note, sizeof(note),
                  "note: the tour needs %d frames to stay within %.3g m and %.3g deg per frame; "
                  "with %d it moves faster",
                  summary.tour_frames_needed, options.tour.max_step, options.tour.max_yaw_step_deg,
                  frames);
    report(options, note);
  }
  return {0, frames};
}

// A handheld camera in one room (default: the largest).
CameraPath plan_handheld(const SyntheticDatasetParams& options, SyntheticDatasetSummary& summary) {
  const synth::World& world = summary.world;
  const Label handheld_room = options.handheld_room ? options.handheld_room : largest_room(world);
  require(handheld_room >= 1 && handheld_room <= world.rooms.size(),
          "synthetic data set: no room " + std::to_string(handheld_room) + " (the world has " +
              std::to_string(world.rooms.size()) + ")");
  summary.trajectory =
      synth::handheld(world, handheld_room, options.frames, hash_key(options.seed, kHandheldSalt));
  return {handheld_room, options.frames};
}

// The floor plan with and without furniture, its rooms and semantic classes (7 files).
synth::FloorPlan write_floor_plan(const std::filesystem::path& dir, const synth::World& world,
                                  const SyntheticDatasetParams& options) {
  synth::FloorPlanParams plan_options;
  plan_options.resolution = options.floor_plan_resolution;
  const synth::FloorPlan plan = synth::make_floor_plan(world, plan_options);
  plan_options.furniture = false;
  const synth::FloorPlan plain = synth::make_floor_plan(world, plan_options);
  write_ros_map(dir / "floor_plan.yaml", plan.grid);
  write_png_map(dir / "floor_plan.png", plan.grid);
  write_png_map(dir / "floor_plan_plain.png", plain.grid);
  GrayImage segmentation(plan.rooms.width(), plan.rooms.height(), 0);
  for (int y = 0; y < plan.rooms.height(); ++y) {
    for (int x = 0; x < plan.rooms.width(); ++x) segmentation(x, y) = plan.rooms(x, y) ? 255 : 0;
  }
  write_png(dir / "floor_plan_gt_segmentation.png", segmentation);
  write_label_png(dir / "rooms.png", plan.rooms);
  write_semantic_png(dir / "semantic_grid.png", plan.semantic);
  return plan;
}

// Where the laser scan was taken, and with which settings.
struct ScanSetup {
  Eigen::Isometry3d pose;
  synth::LidarScanParams laser;
};

// The laser scan from the default pose: the cloud, its planes and its classes (3 files).
ScanSetup write_laser_scan(const std::filesystem::path& dir, const synth::World& world,
                           const SyntheticDatasetParams& options, int threads) {
  const synth::RayCaster caster(world);
  synth::LidarScanParams laser = options.laser;
  laser.threads = threads;
  const Eigen::Isometry3d scan_pose = synth::default_scan_pose(world);
  const synth::LaserScan scan =
      synth::scan_laser(caster, scan_pose, laser, hash_key(options.seed, kLaserSalt));
  PcdCloud cloud = to_pcd(scan.points);
  cloud.viewpoint = scan_pose;
  cloud.labels.assign(scan.plane_id.pixels().begin(), scan.plane_id.pixels().end());
  write_pcd(dir / "laser_scan.pcd", cloud, PcdEncoding::ascii);
  write_label_png(dir / "laser_scan_planes.png", scan.plane_id);
  write_semantic_png(dir / "laser_scan_semantic.png", scan.semantic);
  return {scan_pose, laser};
}

Json laser_scan_json(const ScanSetup& scan) {
  const synth::LidarScanParams& laser = scan.laser;
  return {{"pose", pose_json(scan.pose)},
          {"columns", laser.columns},
          {"lines", laser.lines},
          {"horizontal_fov_deg", laser.horizontal_fov_deg},
          {"min_elevation_deg", laser.min_elevation_deg},
          {"max_elevation_deg", laser.max_elevation_deg},
          {"range_sigma", laser.range_sigma},
          {"frame",
           "sensor: x forward, y left, z up; row 0 = highest elevation, column 0 = rightmost"}};
}

// world.json's "dataset": how the frames, the floor plan and the scan were made.
Json dataset_json(const SyntheticDatasetParams& options, const SyntheticDatasetSummary& summary,
                  Label handheld_room, const synth::FloorPlan& plan, const ScanSetup& scan) {
  Json dataset;
  dataset["frames"] = summary.trajectory.size();
  dataset["trajectory"] = options.trajectory == SyntheticTrajectory::robot ? "robot" : "handheld";
  if (handheld_room) dataset["handheld_room"] = handheld_room;
  dataset["frame_rate"] =
      options.trajectory == SyntheticTrajectory::robot ? options.tour.frame_rate : 30.0;
  dataset["intrinsics"] = {
      {"width", options.intrinsics.width}, {"height", options.intrinsics.height},
      {"fx", options.intrinsics.fx},       {"fy", options.intrinsics.fy},
      {"cx", options.intrinsics.cx},       {"cy", options.intrinsics.cy}};
  dataset["depth_units_per_metre"] = synth::kTumDepthUnitsPerMetre;
  dataset["noise"] = noise_json(options.noise);
  dataset["floor_plan"] = {{"resolution", plan.grid.resolution},
                           {"origin", to_json(Eigen::Vector3d(plan.grid.origin))},
                           {"width", plan.grid.width()},
                           {"height", plan.grid.height()}};
  dataset["laser_scan"] = laser_scan_json(scan);
  return dataset;
}

}  // namespace

std::uint64_t synthetic_frame_seed(std::uint64_t dataset_seed, std::size_t frame) {
  return hash_key(dataset_seed, static_cast<std::uint64_t>(frame), kFrameSalt);
}

std::string timestamp_name(double timestamp) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.6f", timestamp);
  return text;
}

SyntheticDatasetSummary write_synthetic_dataset(const std::filesystem::path& dir,
                                                const SyntheticDatasetParams& options) {
  check_options(options);
  prepare_folder(dir, options.force);
  const int threads = options.threads > 0
                          ? options.threads
                          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));

  SyntheticDatasetSummary summary;
  summary.world = synth::make_building(options.seed, options.building);
  const synth::World& world = summary.world;
  report(options, "world: seed " + std::to_string(options.seed) + ", " +
                      std::to_string(world.rooms.size()) + " rooms (corridor included), " +
                      std::to_string(world.doorways.size()) + " doorways, " +
                      std::to_string(world.furniture.size()) + " pieces of furniture, " +
                      std::to_string(world.planes.size()) + " planes");
  const CameraPath path = options.trajectory == SyntheticTrajectory::robot
                              ? plan_robot_tour(options, summary)
                              : plan_handheld(options, summary);
  const Trajectory& trajectory = summary.trajectory;

  // Twice as many workers as cores: while one waits for its files to reach the disk (the atomic
  // writes fsync), another renders.
  report(options, "rendering " + std::to_string(path.frames) + " frames of " +
                      std::to_string(options.intrinsics.width) + "x" +
                      std::to_string(options.intrinsics.height) + " on " + std::to_string(threads) +
                      " threads");
  write_frames(dir, world, trajectory, options, 2 * threads);
  summary.files += 4 * trajectory.size();

  write_text(dir / "rgb.txt", frame_list("color images", "rgb", trajectory, options.seed));
  write_text(dir / "depth.txt", frame_list("depth maps", "depth", trajectory, options.seed));
  write_tum_trajectory(dir / "groundtruth.txt", trajectory);
  write_camera_intrinsics_json(dir / "camera_intrinsics.json", options.intrinsics);
  summary.files += 4;

  report(options, "floor plan, laser scan, world.json");
  const synth::FloorPlan plan = write_floor_plan(dir, world, options);
  summary.files += 7;
  const ScanSetup scan = write_laser_scan(dir, world, options, threads);
  write_png(dir / "preview.png", synth::floor_plan_preview(plan, trajectory, scan.pose));
  summary.files += 4;

  Json json = world_json(world);
  json["dataset"] = dataset_json(options, summary, path.handheld_room, plan, scan);
  write_text(dir / "world.json", json.dump(1) + "\n");
  summary.files += 1;
  return summary;
}

std::optional<FloorPlanTruth> read_floor_plan_truth(const std::filesystem::path& dir) {
  const std::filesystem::path files[] = {dir / "floor_plan.yaml", dir / "rooms.png",
                                         dir / "semantic_grid.png"};
  int present = 0;
  for (const auto& file : files) present += std::filesystem::exists(file);
  if (present == 0) return std::nullopt;
  for (const auto& file : files)
    require(std::filesystem::exists(file), "floor plan ground truth in " + dir.string() + ": " +
                                               file.filename().string() + " is missing");
  FloorPlanTruth truth{read_ros_map(files[0]), read_label_png(files[1]),
                       read_semantic_png(files[2])};
  for (const auto& [size, name] :
       {std::pair{Eigen::Vector2i(truth.rooms.width(), truth.rooms.height()), "rooms.png"},
        std::pair{Eigen::Vector2i(truth.classes.width(), truth.classes.height()),
                  "semantic_grid.png"}})
    require(size == Eigen::Vector2i(truth.plan.width(), truth.plan.height()),
            "floor plan ground truth in " + dir.string() + ": " + name +
                " differs in size from floor_plan.yaml's map");
  return truth;
}

}  // namespace kartograf::io
