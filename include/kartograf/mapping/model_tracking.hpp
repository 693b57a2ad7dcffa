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
  registration::IcpParams icp =
      registration::odometry_icp_params(registration::OdometryMethod::point_to_plane);
  int icp_width = 320;  // as registration::OdometryParams
  // As the odometry: pairs weighted by depth noise, and where the frame's own geometry leaves
  // directions nearly free (degenerate, from the level at most information_width wide), a motion
  // prior of this strength around the prediction decides them.
  registration::DepthWeightParams depth_weights;
  int information_width = 80;
  double motion_prior = 0.03;
  double min_fitness = 0.3;
  double max_correction_m = 0.05;
  double max_correction_deg = 3;

  static TsdfVolumeParams default_volume();  // 2 cm voxels, 8 cm truncation, 2^16 blocks
  void validate() const;
};

struct ModelTrackingStep {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // camera to world, as fused
  bool from_model = false;                                 // the model's registration was kept
  bool degenerate = false;  // the frame's geometry left directions to the prediction
  double fitness = 0;       // the model's registration (0 on the first frame)
  double inlier_rmse_m = 0;
  std::string reason;  // why the prediction stood (empty when the model's pose was kept)
};

class ModelTracker {
 public:
  // Throws Error on invalid intrinsics, range or parameters.
  ModelTracker(const compute::Context& context, const PinholeIntrinsics& camera,
               const geometry::DepthRange& range, const ModelTrackingParams& params);

  // The frame's pose from `predicted` (camera to world) and the model; fuses the frame there.
  ModelTrackingStep track(const DepthImage& depth, const RgbImage* color,
                          const Eigen::Isometry3d& predicted);

  const TsdfVolume& volume() const { return volume_; }

 private:
  std::string rejection(const registration::IcpResult& result) const;

  const compute::Context* context_;
  PinholeIntrinsics camera_;
  geometry::DepthRange range_;
  ModelTrackingParams params_;
  int first_level_ = 0;
  int information_level_ = 0;
  TsdfVolume volume_;
  geometry::DepthBackprojector projector_;
  PinholeIntrinsics target_camera_;  // ICP's first level: where the model is ray cast
  registration::FramePyramid source_, target_;
  registration::IcpEngine engine_;
  FrameUpload frame_;
  bool empty_ = true;
};

}  // namespace kartograf::mapping
