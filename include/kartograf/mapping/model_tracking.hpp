#pragma once
// Frame-to-model tracking (KinectFusion, Newcombe et al. 2011): each new frame is registered
// against the surface of everything fused so far, ray cast from where the frame is predicted to
// be, instead of against the previous frame alone; then it is fused at the pose found.
//
// The frame-to-frame odometry (registration/odometry.hpp) supplies the prediction: the model
// pose of the last frame moved by the odometry's relative motion since. Point-to-plane ICP of the
// frame's pyramid (from the first level at most icp_width wide) against the pyramid of the surface
// ray cast at that level's resolution refines it. The model's answer is kept only when ICP found
// pairs with fitness at least min_fitness and moved the prediction by at most max_correction_m /
// max_correction_deg (a larger move is the model disagreeing with a good odometry, more likely a
// bad ray cast: a surface the field has not settled on); otherwise the prediction stands and the
// step says why. Either way the frame is then fused at the pose returned.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"
#include "kartograf/registration/depth_weighted_finder.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::mapping {

struct ModelTrackingParams {
  bool enabled = false;
  TsdfVolumeParams volume = default_volume();
  registration::IcpParams icp = default_icp();
  // As registration::OdometryParams. 160x120 of a 640x480 frame: the ray cast is a quarter of
  // 320x240's, and the ATE the same within noise (7-Scenes 0-599 2.50 cm against 2.41 cm).
  int icp_width = 160;
  // As the odometry: pairs weighted by depth noise, and where the frame's own geometry leaves
  // directions nearly free (degenerate, from the level at most information_width wide), a motion
  // prior of this strength around the prediction decides them. The weights are 1 / z^4 over the
  // whole depth range (the depth range's nearest end): the model's surface is averaged over many
  // frames, so a pair's error is the new frame's depth noise alone, growing as z^2 at every depth.
  // Frame-to-frame keeps them flat up to 1.5 m, where both frames' noise is alike.
  registration::DepthWeightParams depth_weights{0.1};
  int information_width = 80;
  double motion_prior = 0.03;
  double min_fitness = 0.3;
  double max_correction_m = 0.05;
  double max_correction_deg = 3;
  // Memory stays bounded: when the model's pool is this full before a frame is fused, the
  // blocks the camera has not seen for longest are evicted, down to half this (among those
  // last seen together, the farthest first): what the camera has been looking at stays. What
  // it sees again is fused anew. A frame at 2 cm voxels adds at most a few thousand blocks.
  double evict_fill = 0.75;

  // 2 cm voxels, 8 cm truncation, 2^16 blocks (fewer where the device's largest buffer holds
  // fewer: the tracker lowers max_blocks to fit); observations beyond 1.5 m weigh (1.5 / z)^4,
  // the pairs' noise model (7-Scenes 0-599 2.31 -> 2.26 cm).
  static TsdfVolumeParams default_volume();
  // The odometry's point-to-plane levels with pairs whose normals agree within 20 degrees (PCL's
  // KinFu's gate), not 45: the model's normals are smooth, and pairs across its rounded edges
  // and corners (a voxel wide) are what the wider gate lets in. On noise-free synthetic frames
  // against a model fused at the true poses the correction falls from 0.46 to 0.23 mm.
  static registration::IcpParams default_icp();
  void validate() const;
  // The frame-to-frame odometry that predicts each frame: `odometry` at ICP's width (so that the
  // tracker reads the odometry's pyramid instead of building its own), without re-estimation
  // every k frames (the model holds the drift; 7-Scenes 0-599 2.50 cm either way, 8 ms less).
  registration::OdometryParams predicting(registration::OdometryParams odometry) const;
};

struct ModelTrackingStep {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // camera to world, as fused
  bool from_model = false;                                 // the model's registration was kept
  bool degenerate = false;  // the frame's geometry left directions to the prediction
  double fitness = 0;       // the model's registration (0 on the first frame)
  double inlier_rmse_m = 0;
  std::size_t evicted_blocks = 0;  // the model was full: blocks least recently seen went
  std::string reason;  // why the prediction stood (empty when the model's pose was kept)
};

class ModelTracker {
 public:
  // Throws Error on invalid intrinsics, range or parameters.
  ModelTracker(const compute::Context& context, const PinholeIntrinsics& camera,
               const geometry::DepthRange& range, const ModelTrackingParams& params);

  // The frame's pose from `predicted` (camera to world) and the model; fuses the frame there.
  // `pyramid`: the frame's pyramid where the caller has one (the odometry's latest_pyramid(),
  // with predicting()'s parameters); else the tracker builds its own. Throws Error when the
  // pyramid is of another camera or lacks ICP's levels or their normals.
  ModelTrackingStep track(const DepthImage& depth, const RgbImage* color,
                          const Eigen::Isometry3d& predicted,
                          const registration::FramePyramid* pyramid = nullptr);

  // Whether `pyramid` can stand for the tracker's own (track()'s pyramid argument): the same
  // camera, ICP's levels, normals on them. Not so for the planar odometry's (one ICP level).
  bool can_register(const registration::FramePyramid& pyramid) const;

  const TsdfVolume& volume() const { return volume_; }

 private:
  std::string rejection(const registration::IcpResult& result) const;
  int source_levels() const;
  // The blocks least recently seen evicted (see evict_fill; `camera_to_world` breaks ties by
  // distance); how many.
  std::size_t evict_least_recently_seen(const Eigen::Isometry3d& camera_to_world);
  bool has_icp_levels(const registration::FramePyramid& pyramid) const;
  const registration::FramePyramid& source_pyramid(const registration::FramePyramid* given);
  registration::IcpResult register_frame(const registration::FramePyramid& source,
                                         const Eigen::Isometry3d& predicted,
                                         ModelTrackingStep& step);

  const compute::Context* context_;
  PinholeIntrinsics camera_;
  geometry::DepthRange range_;
  ModelTrackingParams params_;
  int first_level_ = 0;
  int information_level_ = 0;
  TsdfVolume volume_;
  geometry::DepthBackprojector projector_;
  PinholeIntrinsics target_camera_;  // ICP's first level: where the model is ray cast
  std::optional<registration::FramePyramid> source_;  // made when no pyramid is given
  registration::FramePyramid target_;
  registration::IcpEngine engine_;
  FrameUpload frame_;
  bool empty_ = true;
};

}  // namespace kartograf::mapping
