#pragma once
// Writes a synthetic data set (synth/*) to disk: a TUM RGB-D folder that io::open_tum_sequence
// opens (with its intrinsics and ground-truth poses), the per-frame ground-truth images, the
// world's description, the 2-D ground truth of the floor plan and a 3-D laser scan.
//
//   DIR/rgb/<t>.png  depth/<t>.png      TUM layout (depth 16-bit, 5000 units/m, 0 = no return)
//   DIR/rgb.txt depth.txt groundtruth.txt   TUM lists and poses (camera-to-world)
//   DIR/camera_intrinsics.json          Open3D PinholeCameraIntrinsic
//   DIR/gt/planes/<t>.png               16-bit plane ids (world.json "planes"), 0 = none
//   DIR/gt/semantic/<t>.png             8-bit SemanticClass values
//   DIR/world.json                      building, rooms, doorways, furniture, planes, materials,
//                                       route, and how the data set was made
//   DIR/floor_plan.pgm + .yaml          ROS map_server occupancy map (with furniture)
//   DIR/floor_plan.png                  ipa style: free 255, everything else 0 (with furniture)
//   DIR/floor_plan_plain.png            the same without furniture and door leaves
//   DIR/floor_plan_gt_segmentation.png  ipa ground truth: rooms white (255), doorways closed
//   DIR/rooms.png                       16-bit room ids on the floor-plan grid
//   DIR/semantic_grid.png               8-bit SemanticClass per floor-plan cell
//   DIR/laser_scan.pcd                  organized scan (sensor frame, VIEWPOINT = its pose),
//                                       label = plane id; laser_scan_planes.png,
//                                       laser_scan_semantic.png: its ground truth
//   DIR/preview.png                     the floor plan with the trajectory drawn
//
// <t> is the timestamp with 6 decimals. Everything is deterministic in the options: two runs
// give byte-identical files (frames are rendered in parallel, each from its own noise seed).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/trajectory.hpp"
#include "kartograf/synth/laser_scan.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::io {

enum class SyntheticTrajectory { robot, handheld };

struct SyntheticDatasetParams {
  std::uint64_t seed = 1;
  int frames = 300;  // robot tours: 0 = as many as the tour needs to keep its per-frame limits
  SyntheticTrajectory trajectory = SyntheticTrajectory::robot;
  Label handheld_room = 0;  // handheld: a World::rooms id; 0 = the largest room
  PinholeIntrinsics intrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};  // TUM's default Kinect
  synth::NoiseModel noise = synth::NoiseModel::kinect();
  synth::BuildingParams building;
  synth::TourParams tour;
  synth::LidarScanParams laser;
  double floor_plan_resolution = 0.05;
  // Write into a folder that is not empty (files of the same names are replaced; others, such
  // as frames of an earlier, longer run, are left alone and are not listed in rgb.txt).
  bool force = false;
  int threads = 0;  // cores to use (0: all); frames go to twice as many workers (I/O overlap)
  // Called with progress lines (the CLI prints them on stderr); may be empty.
  std::function<void(const std::string&)> progress;
};

struct SyntheticDatasetSummary {
  synth::World world;
  Trajectory trajectory;
  std::size_t files = 0;       // files written
  int tour_frames_needed = 0;  // robot tours: frames below which the per-frame limits are exceeded
};

// The noise seed of frame `frame` of a data set written with seed `dataset_seed`: rendered with
// it, a frame equals the one `write_synthetic_dataset` writes (tests re-render stretches).
std::uint64_t synthetic_frame_seed(std::uint64_t dataset_seed, std::size_t frame);

// Throws Error naming the folder when it exists and is not empty (unless options.force) or
// cannot be created, and naming the file when a write fails.
SyntheticDatasetSummary write_synthetic_dataset(const std::filesystem::path& dir,
                                                const SyntheticDatasetParams& options);

// The floor plan a data set folder holds as ground truth (floor_plan.yaml + .pgm, rooms.png,
// semantic_grid.png), as pipeline/map_evaluation.hpp takes it; nullopt when the folder has none of
// them. Throws Error when only some are there or one cannot be read.
struct FloorPlanTruth {
  OccupancyGrid plan;
  LabelImage rooms;
  SemanticImage classes;
};
std::optional<FloorPlanTruth> read_floor_plan_truth(const std::filesystem::path& dir);

// The TUM file name stem of a timestamp: 6 decimals ("1.033333").
std::string timestamp_name(double timestamp);

}  // namespace kartograf::io
