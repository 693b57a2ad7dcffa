#pragma once
// The end-to-end mapping pipeline behind `kartograf map`: an RGB-D sequence in, everything a robot
// needs out, in one gravity-aligned map frame (z up, the floor at z = 0, x and y those of the
// first camera's heading).
//
//   1. slam       odometry, loop closure, pose graph, fused coloured map (mapping/slam.hpp, M3)
//   2. views      every label_step-th frame at its optimised pose (at most max_views of them),
//                 at most label_width pixels wide: per-pixel semantic classes
//                 (semantic/classify.hpp, M2) and planes (segmentation/plane_extraction.hpp, M1),
//                 pooled in the map (semantic/labelled_views.hpp, mapping/plane_map.hpp); the views
//                 vote for up
//   3. gravity    the voted up becomes +z; the floor's median height becomes z = 0
//   4. grid       the metric-semantic grid (semantic/semantic_grid.hpp): floor evidence free,
//                 obstacles in the robot's height band, doors, traversability; the occupancy grid
//                 is its free / occupied / unknown view
//   5. rooms      room segmentation of the occupancy grid (rooms/room_methods.hpp, M4), with
//                 the grid's doorways closed (rooms end at the doors the semantic grid found);
//                 then each room takes the furniture and unobserved cells its walls enclose, and
//                 small fragments join the room they touch
// Library only: pipeline/map_evaluation.hpp scores a result against ground truth and
// io/map_outputs.hpp writes the files and the report.
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/triangle_mesh.hpp"
#include "kartograf/features/orb_front_end.hpp"
#include "kartograf/mapping/frame_source.hpp"
#include "kartograf/mapping/plane_map.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/rooms/room_methods.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/semantic/semantic_grid.hpp"

namespace kartograf::pipeline {

// Plane extraction on decimated views: planes of a quarter of the default's pixels count.
segmentation::PlaneExtractionParams view_plane_params();

// ORB for whole sequences: a low FAST threshold, since the synthetic world's smooth textures give
// too few corners at OpenCV's default (20: 43-49 per 640x480 frame, 5: 270-350), and 3000 corners
// a frame: on a tiled floor or a striped wall most corners repeat and Lowe's ratio test drops
// them, and of 1000 too few distinct ones were left for RANSAC's consensus where the geometry
// leaves the robot's step to the features (docs/slam.md, "The features' budget").
features::OrbParams map_orb_params();

struct MapPipelineParams {
  mapping::SlamParams slam;  // its build_map is always on
  // Local features (ORB) for the SLAM: loop-closure candidates by appearance and the odometry's
  // recovery from a lost frame (they fill slam.features and slam.odometry.features).
  bool features = true;
  features::OrbParams orb = map_orb_params();
  // A trajectory known beforehand (e.g. ground truth): stage 1 only fuses the map at these poses
  // (mapping::run_with_known_poses). Empty: SLAM estimates them.
  mapping::KnownPoseLookup known_poses;
  std::size_t label_step = 5;  // views: every k-th frame
  // views: at most this many, spread evenly (every max(label_step, ceil(frames / max_views))-th
  // frame), so that the pooled views' memory is bounded on long runs (about 2.7 MB a 320x240 view
  // on the survey: 0.8 GB for 300).
  std::size_t max_views = 300;
  int label_width = 320;                // views: decimated to at most this many pixels per row
  semantic::LabellingParams labelling;  // gravity.prior_up defaults to the camera's -y
  segmentation::PlaneExtractionParams planes = view_plane_params();
  mapping::PlaneMapParams plane_map;
  semantic::SemanticGridParams grid;
  rooms::RoomMethod room_method = rooms::RoomMethod::distance;
  rooms::RoomMethodParams rooms;
  bool rooms_end_at_doorways = true;  // doorway cells count as occupied for the segmentation
  // Islands of unseen cells up to this area inside the map (an open door's leaf and its shadow in
  // a corridor; a corridor's middle that no view saw from its ends) count as free for the
  // segmentation (rooms::free_unseen_islands); 0: off. A room is larger than 1 m^2, so no island
  // freed is a room no view entered.
  double room_unseen_island_m2 = 1.0;
  // Rooms take the unlabelled cells their walls and doorways enclose: furniture, floor the views
  // missed (rooms::extend_rooms_over_enclosed). Off: rooms cover observed free floor only.
  bool rooms_take_enclosed = true;
  // Then rooms under this area touching another room directly (no wall or doorway between: a
  // corner cut off by furniture) join it (rooms::merge_room_fragments); 0: off.
  double room_fragment_area_m2 = 2.0;

  void validate() const;  // throws Error naming the first bad field
};

// Stages in run order, with their names as reported ("slam", "views", "gravity", "grid", "rooms").
struct StageTiming {
  std::string stage;
  double seconds = 0;
};

// What the TSDF of the online mapper (mapper.hpp) did, and what the mapper keeps for later passes.
struct VolumeStats {
  std::size_t blocks = 0;       // in the live volume now
  std::size_t peak_blocks = 0;  // the most it held
  std::size_t budget_blocks = 0;
  std::size_t evictions = 0;  // rebuilds around the camera (the budget was reached)
  std::size_t refusions = 0;  // rebuilds at moved poses
  std::size_t fused_frames = 0;
  double fusion_seconds = 0;           // integration and rebuilds
  bool covers_all_frames = true;       // false after an eviction: the volume holds the nearby part
  std::size_t store_memory_bytes = 0;  // the kept frames in memory (up to 64 MiB)
  std::size_t store_disk_bytes = 0;    // and in a temporary file
  // The loop closure's keyframes (depth, samples, features) in memory (up to 32 + 16 MiB by
  // default) and in temporary files.
  std::size_t keyframe_memory_bytes = 0;
  std::size_t keyframe_disk_bytes = 0;
};

struct MapPipelineResult {
  mapping::SlamResult slam;  // in the SLAM frame (the first camera's)
  Eigen::Isometry3d map_from_slam = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Isometry3d> poses;  // camera-to-map, one per frame
  PointCloud map;                        // the map in the map frame: the mesh's vertices
  TriangleMesh mesh;                     // the TSDF's surface, map frame
  OccupancyGrid band_occupancy;          // the TSDF's height band (mapping/tsdf_slice.hpp)
  Image<float> esdf;                     // metres, of band_occupancy (mapping::occupancy_esdf)
  VolumeStats volume;
  std::vector<mapping::MapPlane> planes;  // map frame
  semantic::SemanticGrid semantic;
  OccupancyGrid occupancy;               // the grid's free / occupied / unknown cells
  rooms::RoomSegmentation rooms;         // on `occupancy` (see rooms_take_enclosed)
  std::size_t enclosed_cells_taken = 0;  // cells beyond the free space the rooms took
  int labelled_views = 0, unlabelled_views = 0;
  std::string first_unlabelled_reason;
  std::vector<StageTiming> timings;
  double total_seconds() const;
};

struct MapPipelineObserver {
  mapping::SlamObserver slam;  // its on_progress also reports stage "views"
  std::function<void(std::string_view stage)> on_stage;  // when a stage starts
};

// Stages 2-5 on result.slam's poses (filled by the caller, with result.timings' "slam"), the views
// read from `views` (frame(i) for every label_step-th i, any width: decimated to label_width).
// Fills the rest of the result but map, mesh, band_occupancy, esdf and volume.
void complete_map(const compute::Context& context, const mapping::FrameSource& views,
                  const MapPipelineParams& params, const MapPipelineObserver& observer,
                  MapPipelineResult& result);

}  // namespace kartograf::pipeline
