#pragma once
// The online mapper: a robot hands it RGB-D frames as they come and asks for the map whenever it
// needs it. `kartograf map` and run_map_pipeline are this loop over a sequence.
//
//   add_frame   tracks the frame (mapping/online_slam.hpp: odometry, loop closure, pose graph) or
//               takes the pose it is given, returns the pose and a status at once, keeps the frame
//               decimated (mapping/frame_store.hpp: a temporary file, not memory) and fuses it
//               into the live TSDF (mapping/tsdf_volume.hpp) at its current pose.
//   mesh        the TSDF's surface (mapping/tsdf_mesh.hpp).
//   distance_field  the TSDF's 3-D distance field (mapping/esdf_volume.hpp), brought up to date
//               with the frames fused since it was last asked for (milliseconds, not seconds).
//   snapshot    the map as the batch pipeline makes it at the current poses: views labelled and
//               pooled, gravity, the semantic grid, rooms (map_pipeline.hpp's stages 2-5), plus the
//               occupancy grid of the robot's height band from the TSDF and its distance field.
//               Costs seconds per hundred kept views; kept until the next frame.
//   finish      the final pose-graph optimisation, then a snapshot.
//
// Memory policy. The TSDF is a pool of volume.max_blocks blocks (the budget: 6 KiB a block, fixed
// when the mapper is made); frames live on disk. When a loop closure moves earlier poses the live
// volume is stale and is re-fused from the kept frames at their new poses before the next mesh or
// snapshot. When fusing would take the pool past high_water of its budget, the volume is rebuilt
// from the kept frames whose cameras lie within keep_radius_m of the current camera (the far part
// is evicted; it comes back when the camera returns), halving the radius until they fit. A
// mesh of a map larger than the budget therefore covers the camera's surroundings only; the
// step's and the result's volume statistics say when that happened.
// What else is held, each with its own bound: the kept frames' first 64 MiB (the rest in a
// temporary file); the loop closure's keyframe depth (32 MiB) and its newest keyframes' samples
// and features (16 MiB; both LoopClosureParams, the rest in temporary files); a snapshot's pooled
// views (at most pipeline.max_views of them, about 2.7 MB each at 320x240, freed when the grid is
// built). What grows with the run: per frame its pose and tracking record, per keyframe the place
// index's descriptors (about 10 KB). docs/volumetric.md has the measured figures.
#include <cstddef>
#include <memory>
#include <optional>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/triangle_mesh.hpp"
#include "kartograf/mapping/esdf_volume.hpp"
#include "kartograf/mapping/tsdf_mesh.hpp"
#include "kartograf/mapping/tsdf_slice.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"

namespace kartograf::pipeline {

// The mapper's TSDF: 4 cm voxels (planning maps' usual size; nvblox's default is 5 cm), a
// truncation of 3 voxels, the default budget of 16384 blocks (96 MiB, 2 600 m^2 of surface).
mapping::TsdfVolumeParams mapper_volume_params();

struct MapperParams {
  MapPipelineParams pipeline;  // SLAM, views, grid and rooms, as the batch pipeline
  mapping::TsdfVolumeParams volume = mapper_volume_params();
  int fusion_width = 320;           // frames are kept and fused at most this wide (decimated)
  double max_fusion_depth_m = 4.0;  // depth beyond this is not fused (noise grows as depth^2)
  double high_water = 0.85;         // of volume.max_blocks
  double keep_radius_m = 8.0;
  // Fuse each frame as it comes (a robot asking for the map while it runs). Off: the volume is
  // fused once, when the map is first asked for (a batch run: run_map_pipeline).
  bool live_fusion = true;
  mapping::MeshParams mesh;
  mapping::TsdfSliceParams slice;  // world_to_level and floor_z come from the snapshot's gravity
  mapping::EsdfVolumeParams distance_field;

  void validate() const;  // Error naming the first bad field
};

enum class FrameStatus {
  tracked,   // registered
  fallback,  // every registration rejected: the motion model's prediction (tracking is weak)
  given,     // the caller gave the pose
};

const char* to_string(FrameStatus status);

struct MapperStep {
  std::size_t frame = 0;
  // Camera-to-world in the SLAM frame (the first camera's), the current estimate.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  FrameStatus status = FrameStatus::tracked;
  bool keyframe = false;
  bool poses_moved = false;  // a loop closure moved earlier poses (the volume will be re-fused)
  bool evicted = false;      // the volume was rebuilt around the camera for this frame
  double fitness = 0;        // of the registration against the previous frame (0: none)
  double seconds = 0;        // add_frame, all of it
};

class Mapper {
 public:
  // Throws Error on invalid intrinsics or parameters, or a budget the device cannot hold.
  Mapper(const compute::Context& context, const PinholeIntrinsics& camera,
         double depth_units_per_metre, const MapperParams& params = {},
         const MapPipelineObserver& observer = {});
  ~Mapper();
  Mapper(Mapper&&) noexcept;
  Mapper& operator=(Mapper&&) noexcept;

  // Depth in the given units, colour on the depth camera's pixel grid (may be empty). A pose
  // (camera-to-world, any world) is either given with every frame or with none: with poses the
  // mapper only fuses, and poses are taken relative to the first frame's. Throws Error on a
  // frame of another size, a pose that is not rigid, or a mix of given and missing poses.
  MapperStep add_frame(const registration::RgbdImages& frame,
                       const std::optional<Eigen::Isometry3d>& pose = std::nullopt);

  std::size_t frame_count() const;
  const std::vector<Eigen::Isometry3d>& poses() const;  // SLAM frame, current estimates
  // The live volume's surface in the SLAM frame (re-fused first if poses moved).
  TriangleMesh mesh();
  // The live volume's 3-D distance field in the SLAM frame (re-fused first if poses moved; the
  // field then starts again), updated incrementally; valid until the next call.
  const mapping::EsdfGrid& distance_field();
  // Stages 2-5 at the current poses; Error when no view can be labelled or no floor was seen.
  const MapPipelineResult& snapshot();
  const semantic::SemanticGrid& semantic() { return snapshot().semantic; }
  const rooms::RoomSegmentation& rooms() { return snapshot().rooms; }
  const OccupancyGrid& occupancy() { return snapshot().band_occupancy; }
  const Image<float>& esdf() { return snapshot().esdf; }
  VolumeStats volume_stats() const;

  // The final optimisation and the full result (map frame). Once only; add_frame afterwards is
  // an Error.
  MapPipelineResult finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The mapper fed with every frame of the source (read one ahead on a second thread; with
// params.pipeline.known_poses, at those poses), then finished; without live fusion (the volume is
// fused once, at the final poses: the same field, half the work). Throws Error when a stage cannot
// go on (no frame, bad parameters, no view could be labelled, no floor seen, ...), naming the
// stage.
MapPipelineResult run_map_pipeline(const compute::Context& context,
                                   const mapping::FrameSource& source,
                                   const MapperParams& params = {},
                                   const MapPipelineObserver& observer = {});

}  // namespace kartograf::pipeline
