#include "kartograf/pipeline/mapper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "kartograf/core/color.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/pose.hpp"
#include "kartograf/features/orb_front_end.hpp"
#include "kartograf/mapping/frame_store.hpp"
#include "kartograf/mapping/online_slam.hpp"

namespace kartograf::pipeline {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void require_rigid(const Eigen::Isometry3d& pose, std::size_t frame) {
  require(is_rigid(pose), "mapper: the pose given with frame " + std::to_string(frame) +
                              " is not finite or not a rotation");
}

// The mesh in another frame, and its vertices as the map's point cloud (normals from the faces
// around each vertex).
PointCloud mesh_points(const TriangleMesh& mesh) {
  PointCloud cloud;
  cloud.points = mesh.vertices;
  cloud.normals.assign(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (int k = 0; k < 3; ++k) cloud.normals[t[k]] += n;
  }
  for (Eigen::Vector3f& n : cloud.normals) n.normalize();
  if (!mesh.colors.empty()) {
    cloud.colors.reserve(mesh.colors.size());
    for (const std::uint32_t c : mesh.colors) cloud.colors.push_back(unpack_rgb(c));
  }
  return cloud;
}

TriangleMesh transformed(TriangleMesh mesh, const Eigen::Isometry3d& transform) {
  const Eigen::Isometry3f t = transform.cast<float>();
  for (Eigen::Vector3f& v : mesh.vertices) v = t * v;
  return mesh;
}

// The live TSDF and the kept frames it is rebuilt from.
class LiveVolume {
 public:
  LiveVolume(const compute::Context& context, const MapperParams& params,
             mapping::FrameStore& store, double depth_units_per_metre)
      : context_(&context), params_(params), store_(&store) {
    range_.units_per_metre = depth_units_per_metre;
    range_.max_metres = params.max_fusion_depth_m;
    stats_.budget_blocks = params.volume.max_blocks;
    volume_.emplace(context, params.volume);
  }

  // Fuses the newest kept (decimated) frame at `pose`, the last of `poses`; when the pool is past
  // high water, evicts instead, rebuilding around it. Returns whether it evicted.
  bool fuse(const registration::RgbdImages& frame, const Eigen::Isometry3d& pose,
            const std::vector<Eigen::Isometry3d>& poses) {
    const auto start = Clock::now();
    const bool evict = above(params_.high_water);
    if (evict) {
      rebuild_around(poses, pose.translation());  // the new frame (kept already) included
    } else {
      integrate(frame, pose);
    }
    stats_.fusion_seconds += seconds_since(start);
    return evict;
  }

  // Re-fuses every kept frame at `poses` (evicting around the last camera if they do not fit).
  void refuse(const std::vector<Eigen::Isometry3d>& poses) {
    const auto start = Clock::now();
    ++stats_.refusions;
    if (rebuild(poses, std::nullopt, 0)) {
      stats_.covers_all_frames = true;
    } else {
      rebuild_around(poses, poses.back().translation());
    }
    stats_.fusion_seconds += seconds_since(start);
  }

  const mapping::TsdfVolume& volume() const { return *volume_; }
  VolumeStats stats() const {
    VolumeStats stats = stats_;
    stats.blocks = volume_->block_count();
    stats.store_memory_bytes = store_->bytes_in_memory();
    stats.store_disk_bytes = store_->bytes_on_disk();
    return stats;
  }

 private:
  bool above(double fraction) const {
    return static_cast<double>(volume_->block_count()) >
           fraction * static_cast<double>(params_.volume.max_blocks);
  }

  void integrate(const registration::RgbdImages& frame, const Eigen::Isometry3d& pose) {
    volume_->integrate(frame.depth, frame.color, store_->camera(), range_, pose);
    ++stats_.fused_frames;
    stats_.peak_blocks = std::max(stats_.peak_blocks, volume_->block_count());
  }

  // A new volume from the kept frames whose cameras lie within `radius` of `centre` (all without
  // a centre). False when they passed high water.
  bool rebuild(const std::vector<Eigen::Isometry3d>& poses,
               const std::optional<Eigen::Vector3d>& centre, double radius) {
    volume_.reset();  // the old pool goes before the new one is allocated
    volume_.emplace(*context_, params_.volume);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (centre && (poses[i].translation() - *centre).norm() > radius) continue;
      if (above(params_.high_water)) return false;
      integrate(store_->frame(i), poses[i]);
    }
    return true;
  }

  // The eviction policy (mapper.hpp): the frames near the camera, within a radius halved until
  // they fill at most 70 % of high water (so that the next eviction is some frames away); below
  // 25 cm, the current frame alone.
  void rebuild_around(const std::vector<Eigen::Isometry3d>& poses, const Eigen::Vector3d& centre) {
    ++stats_.evictions;
    stats_.covers_all_frames = false;
    for (double radius = params_.keep_radius_m; radius >= 0.25; radius /= 2)
      if (rebuild(poses, centre, radius) && !above(0.7 * params_.high_water)) return;
    volume_.reset();
    volume_.emplace(*context_, params_.volume);
    const std::size_t last = poses.size() - 1;
    integrate(store_->frame(last), poses[last]);
    require(!above(params_.high_water),
            "mapper: the TSDF budget of " + std::to_string(params_.volume.max_blocks) +
                " blocks does not hold a single frame; raise it or the voxel size");
  }

  const compute::Context* context_;
  MapperParams params_;
  mapping::FrameStore* store_;
  geometry::DepthRange range_;
  std::optional<mapping::TsdfVolume> volume_;
  VolumeStats stats_;
};

}  // namespace

mapping::TsdfVolumeParams mapper_volume_params() {
  mapping::TsdfVolumeParams params;
  params.voxel_size = 0.04;
  params.truncation = 0.12;
  return params;
}

void MapperParams::validate() const {
  pipeline.validate();
  volume.validate();
  require(fusion_width >= 32, "mapper: fusion_width must be >= 32 pixels");
  require(std::isfinite(max_fusion_depth_m) && max_fusion_depth_m > 0,
          "mapper: max_fusion_depth_m must be finite and positive");
  require(high_water > 0 && high_water <= 1, "mapper: high_water must be in (0, 1]");
  require(std::isfinite(keep_radius_m) && keep_radius_m > 0,
          "mapper: keep_radius_m must be finite and positive");
  slice.validate();
  distance_field.validate();
}

const char* to_string(FrameStatus status) {
  switch (status) {
    case FrameStatus::tracked:
      return "tracked";
    case FrameStatus::fallback:
      return "fallback";
    case FrameStatus::given:
      return "given";
  }
  return "?";
}

struct Mapper::State {
  State(const compute::Context& context, const PinholeIntrinsics& camera, double units,
        const MapperParams& params, const MapPipelineObserver& observer)
      : context(&context),
        params(prepared(params)),
        observer(observer),
        camera(checked(camera)),
        store(camera, units, mapping::decimation_for_width(camera, params.fusion_width)),
        volume(context, params, store, units) {}

  static const PinholeIntrinsics& checked(const PinholeIntrinsics& camera) {
    camera.validate("mapper");
    return camera;
  }

  // Validated, with the local features (ORB) the SLAM uses when params.pipeline.features.
  static MapperParams prepared(MapperParams params) {
    params.validate();
    if (params.pipeline.features) {
      const auto features = std::make_shared<const features::OrbFrontEnd>(params.pipeline.orb);
      params.pipeline.slam.features = features;
      params.pipeline.slam.odometry.features = features;
    }
    params.pipeline.slam.build_map = false;  // the TSDF is the map
    return params;
  }

  // The live volume at the current poses: re-fused if they moved since it fused its frames.
  const mapping::TsdfVolume& current_volume() {
    if (stale && store.size() > 0) volume.refuse(poses());
    stale = false;
    return volume.volume();
  }

  // Stages 2-5 and the volume's products at the poses of `slam`.
  MapPipelineResult complete(mapping::SlamResult slam);

  const std::vector<Eigen::Isometry3d>& poses() const { return slam ? slam->poses() : given; }

  VolumeStats stats() const {
    VolumeStats stats = volume.stats();
    if (slam) {
      stats.keyframe_memory_bytes = slam->keyframe_bytes_in_memory();
      stats.keyframe_disk_bytes = slam->keyframe_bytes_on_disk();
    }
    return stats;
  }

  // The volume's surface; without colour when no frame brought any (a depth camera alone: the
  // voxels' colours are then all black, no colour of the scene).
  TriangleMesh surface(const mapping::TsdfBlocks& blocks) const {
    TriangleMesh mesh = mapping::extract_mesh(blocks, params.mesh);
    if (!coloured) mesh.colors.clear();
    return mesh;
  }

  // The pose of the next frame: tracked, or given (relative to the first given one).
  Eigen::Isometry3d locate(const registration::RgbdImages& frame,
                           const std::optional<Eigen::Isometry3d>& pose, MapperStep& step);

  const compute::Context* context;
  MapperParams params;
  MapPipelineObserver observer;
  PinholeIntrinsics camera;
  mapping::FrameStore store;
  LiveVolume volume;
  std::optional<mapping::OnlineSlam> slam;  // when poses are estimated
  std::optional<bool> poses_given;          // decided by the first frame
  std::vector<Eigen::Isometry3d> given;
  std::vector<double> timestamps;  // given poses' frames
  Eigen::Isometry3d first_inverse = Eigen::Isometry3d::Identity();
  bool stale = false;  // poses moved since the volume fused its frames
  std::optional<MapPipelineResult> snapshot;
  std::optional<mapping::EsdfVolume> distance_field;  // made when first asked for
  mapping::EsdfGrid distance_grid;
  double adding_seconds = 0;
  bool coloured = false;  // some frame brought colour
  bool finished = false;
};

Eigen::Isometry3d Mapper::State::locate(const registration::RgbdImages& frame,
                                        const std::optional<Eigen::Isometry3d>& pose,
                                        MapperStep& step) {
  const std::size_t i = store.size();
  if (!poses_given) {
    poses_given = pose.has_value();
    if (!*poses_given) {
      slam.emplace(*context, camera, store.depth_units_per_metre(), params.pipeline.slam,
                   observer.slam);
    }
  }
  require(pose.has_value() == *poses_given, "mapper: frame " + std::to_string(i) +
                                                (*poses_given ? " has no pose, the first had one"
                                                              : " has a pose, the first had none"));
  if (*poses_given) {
    require_rigid(*pose, i);
    if (i == 0) first_inverse = pose->inverse();
    given.push_back(first_inverse * *pose);
    timestamps.push_back(frame.timestamp);
    step.status = FrameStatus::given;
    return given.back();
  }
  const mapping::SlamStep tracked = slam->add(frame);
  step.status = tracked.odometry.fallback ? FrameStatus::fallback : FrameStatus::tracked;
  step.keyframe = tracked.odometry.keyframe;
  step.poses_moved = tracked.optimised;
  if (tracked.odometry.previous) step.fitness = tracked.odometry.previous->fitness;
  return tracked.pose;
}

MapPipelineResult Mapper::State::complete(mapping::SlamResult slam_result) {
  MapPipelineResult result;
  result.slam = std::move(slam_result);
  result.slam.timing.total_seconds = adding_seconds;
  result.timings.push_back({"slam", adding_seconds});
  complete_map(*context, store, params.pipeline, observer, result);
  const auto start = Clock::now();
  if (observer.on_stage) observer.on_stage("volume");
  if (stale) volume.refuse(result.slam.poses);
  stale = false;
  const mapping::TsdfBlocks blocks = volume.volume().download();
  result.mesh = transformed(surface(blocks), result.map_from_slam);
  result.map = mesh_points(result.mesh);
  mapping::TsdfSliceParams slice = params.slice;
  slice.world_to_level = result.map_from_slam;
  slice.floor_z = 0;
  mapping::TsdfBandMaps band = mapping::tsdf_band_maps(volume.volume(), slice);  // on the device
  result.band_occupancy = std::move(band.occupancy);
  result.esdf = std::move(band.esdf);
  result.volume = stats();
  result.slam.timing.map_seconds = result.volume.fusion_seconds;
  result.timings.push_back({"volume", seconds_since(start)});
  return result;
}

Mapper::Mapper(const compute::Context& context, const PinholeIntrinsics& camera,
               double depth_units_per_metre, const MapperParams& params,
               const MapPipelineObserver& observer)
    : state_(std::make_unique<State>(context, camera, depth_units_per_metre, params, observer)) {}

Mapper::~Mapper() = default;
Mapper::Mapper(Mapper&&) noexcept = default;
Mapper& Mapper::operator=(Mapper&&) noexcept = default;

MapperStep Mapper::add_frame(const registration::RgbdImages& frame,
                             const std::optional<Eigen::Isometry3d>& pose) {
  State& s = *state_;
  require(!s.finished, "mapper: a frame was added after finish()");
  const auto start = Clock::now();
  MapperStep step;
  step.frame = s.store.size();
  s.store.check(frame);
  step.pose = s.locate(frame, pose, step);
  s.stale = s.stale || step.poses_moved;
  s.coloured = s.coloured || !frame.color.empty();
  const registration::RgbdImages kept = s.store.add(frame);
  if (s.params.live_fusion) {
    step.evicted = s.volume.fuse(kept, step.pose, s.poses());
  } else {
    s.stale = true;  // fused when first asked for
  }
  s.snapshot.reset();
  step.seconds = seconds_since(start);
  s.adding_seconds += step.seconds;
  return step;
}

std::size_t Mapper::frame_count() const {
  return state_->store.size();
}

const std::vector<Eigen::Isometry3d>& Mapper::poses() const {
  return state_->poses();
}

VolumeStats Mapper::volume_stats() const {
  return state_->stats();
}

TriangleMesh Mapper::mesh() {
  State& s = *state_;
  return s.surface(s.current_volume().download());
}

const mapping::EsdfGrid& Mapper::distance_field() {
  State& s = *state_;
  const mapping::TsdfVolume& volume = s.current_volume();
  if (!s.distance_field)
    s.distance_field.emplace(*s.context, s.params.volume, s.params.distance_field);
  s.distance_field->update(volume);
  s.distance_grid = s.distance_field->download();
  return s.distance_grid;
}

const MapPipelineResult& Mapper::snapshot() {
  State& s = *state_;
  require(!s.finished, "mapper: snapshot() after finish(); use finish()'s result");
  require(s.store.size() > 0, "mapper: no frame was added yet");
  if (!s.snapshot) {
    mapping::SlamResult slam;
    slam.poses = s.poses();
    slam.poses_given = s.poses_given.value_or(false);
    s.snapshot = s.complete(std::move(slam));
  }
  return *s.snapshot;
}

MapPipelineResult Mapper::finish() {
  State& s = *state_;
  require(!s.finished, "mapper: finish() was called twice");
  require(s.store.size() > 0, "map: the sequence holds no frame");
  s.finished = true;
  mapping::SlamResult slam;
  if (s.slam) {
    slam = s.slam->finish();
    s.stale = true;  // the final optimisation moves every pose a little
  } else {
    slam.poses_given = true;
    slam.poses = s.given;
    slam.odometry.poses = s.given;
    slam.odometry.timestamps = s.timestamps;
  }
  return s.complete(std::move(slam));
}

MapPipelineResult run_map_pipeline(const compute::Context& context,
                                   const mapping::FrameSource& source, const MapperParams& params,
                                   const MapPipelineObserver& observer) {
  require(source.size() > 0, "map: the sequence holds no frame");
  MapperParams batch = params;
  batch.live_fusion = false;  // the volume is fused once, at the final poses
  Mapper mapper(context, source.camera(), source.depth_units_per_metre(), batch, observer);
  if (observer.on_stage) observer.on_stage("slam");
  const mapping::KnownPoseLookup& known = params.pipeline.known_poses;
  const std::size_t total = source.size();
  const mapping::FrameLoopTiming timing =
      for_each_frame(source, 0, total, [&](std::size_t i, registration::RgbdImages& images) {
        mapper.add_frame(images, known ? std::optional(known(i, images)) : std::nullopt);
        if (observer.slam.on_progress) observer.slam.on_progress("odometry", i + 1, total);
      });
  MapPipelineResult result = mapper.finish();
  result.slam.timing.load_seconds = timing.load_seconds;
  result.slam.odometry.timing = timing;
  return result;
}

}  // namespace kartograf::pipeline
