#include "kartograf/mapping/model_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <numeric>
#include <span>

#include "kartograf/core/error.hpp"
#include "kartograf/registration/geometric_information.hpp"
#include "kartograf/registration/projective_association.hpp"

namespace kartograf::mapping {

namespace {

// The camera of pyramid level `level` (level 0: `camera`).
PinholeIntrinsics level_camera(PinholeIntrinsics camera, int level) {
  for (int i = 0; i < level; ++i) camera = registration::half_resolution(camera);
  return camera;
}

registration::PyramidParams pyramid_params(int levels, int first_normals_level = 0) {
  registration::PyramidParams p;
  p.levels = levels;
  p.first_normals_level = first_normals_level;
  return p;
}

// The model's pool lowered to the device's largest buffer where that is smaller (lavapipe:
// 128 MiB, 21845 blocks of 2 cm voxels, about 360 m^2 of surface).
TsdfVolumeParams fitted_to_device(const compute::Context& context, TsdfVolumeParams volume) {
  volume.max_blocks = std::min(volume.max_blocks, TsdfVolume::largest_pool(context));
  return volume;
}

}  // namespace

TsdfVolumeParams ModelTrackingParams::default_volume() {
  TsdfVolumeParams v;
  v.voxel_size = 0.02;
  v.truncation = 0.08;
  v.max_blocks = 1 << 16;
  v.fusion_weight_depth = 1.5;  // the frame-to-frame odometry's reach of flat pair weights
  return v;
}

registration::IcpParams ModelTrackingParams::default_icp() {
  registration::IcpParams icp =
      registration::odometry_icp_params(registration::OdometryMethod::point_to_plane);
  icp.max_normal_angle_deg = 20;
  return icp;
}

registration::OdometryParams ModelTrackingParams::predicting(
    registration::OdometryParams odometry) const {
  odometry.icp_width = icp_width;
  odometry.information_width = information_width;
  odometry.reestimate_interval = 0;
  return odometry;
}

void ModelTrackingParams::validate() const {
  volume.validate();
  require(icp_width > 0 && information_width > 0,
          "model tracking: icp_width and information_width must be > 0");
  require(motion_prior >= 0, "model tracking: motion_prior must be >= 0");
  require(min_fitness >= 0 && min_fitness <= 1, "model tracking: min_fitness must be in [0, 1]");
  require(max_correction_m > 0 && max_correction_deg > 0,
          "model tracking: the largest correction must be > 0");
  require(evict_fill > 0 && evict_fill <= 1, "model tracking: evict_fill must be in (0, 1]");
}

ModelTracker::ModelTracker(const compute::Context& context, const PinholeIntrinsics& camera,
                           const geometry::DepthRange& range, const ModelTrackingParams& params)
    : context_(&context),
      camera_(camera),
      range_(range),
      params_((params.validate(), params)),
      first_level_(registration::pyramid_level_at_most(camera.width, params.icp_width)),
      information_level_(
          registration::pyramid_level_at_most(camera.width, params.information_width)),
      volume_(context, fitted_to_device(context, params.volume)),
      projector_(context, camera, range_),
      target_camera_(level_camera(camera, first_level_)),
      target_(context, target_camera_, pyramid_params(static_cast<int>(params.icp.levels.size()))),
      engine_(context, params.icp,
              std::make_unique<registration::DepthWeightedFinder>(
                  context, std::make_unique<registration::ProjectiveAssociation>(context),
                  params.depth_weights)),
      frame_(context) {}

std::string ModelTracker::rejection(const registration::IcpResult& result) const {
  // Not `converged`: on a ray-cast surface the finest level's updates often stay just above the
  // tolerances until its iteration limit, at a good answer.
  if (result.inlier_count == 0) return "no pairs";
  if (!(result.fitness >= params_.min_fitness)) return "fitness below min_fitness";
  const Eigen::Isometry3d& m = result.source_to_target;
  if (!m.matrix().allFinite()) return "not finite";
  const double degrees = Eigen::AngleAxisd(m.rotation()).angle() * 180 / std::numbers::pi;
  if (m.translation().norm() > params_.max_correction_m || degrees > params_.max_correction_deg) {
    return "moved the prediction too far";
  }
  return {};
}

int ModelTracker::source_levels() const {
  return std::max(first_level_ + static_cast<int>(params_.icp.levels.size()),
                  information_level_ + 1);
}

bool ModelTracker::has_icp_levels(const registration::FramePyramid& pyramid) const {
  return pyramid.level_count() >= source_levels() &&
         pyramid.params().first_normals_level <= std::min(first_level_, information_level_);
}

bool ModelTracker::can_register(const registration::FramePyramid& pyramid) const {
  return pyramid.level(0).camera == camera_ && has_icp_levels(pyramid);
}

const registration::FramePyramid& ModelTracker::source_pyramid(
    const registration::FramePyramid* given) {
  const int finest = std::min(first_level_, information_level_);
  if (given == nullptr) {
    if (!source_) source_.emplace(*context_, camera_, pyramid_params(source_levels(), finest));
    source_->build(projector_, frame_.depth());
    return *source_;
  }
  require(given->level(0).camera == camera_,
          "model tracking: the given pyramid is of another camera than the tracker's");
  require(has_icp_levels(*given),
          "model tracking: the given pyramid has " + std::to_string(given->level_count()) +
              " levels with normals from level " +
              std::to_string(given->params().first_normals_level) + "; ICP needs " +
              std::to_string(source_levels()) + " with normals from level " +
              std::to_string(finest) + " (ModelTrackingParams::predicting)");
  return *given;
}

registration::IcpResult ModelTracker::register_frame(const registration::FramePyramid& source,
                                                     const Eigen::Isometry3d& predicted,
                                                     ModelTrackingStep& step) {
  // Cast at ICP's first level only: the finer level would cost 4x and never be read.
  volume_.raycast(target_camera_, range_, predicted, target_.base_points());
  target_.build();
  const std::vector<registration::CloudView> source_views = source.views();
  const std::vector<registration::CloudView> target_views = target_.views();
  const std::span<const registration::CloudView> source_span =
      std::span(source_views)
          .subspan(static_cast<std::size_t>(first_level_), params_.icp.levels.size());
  const registration::GeometricInformation geometry = registration::geometric_information(
      source.level(information_level_).view(), params_.depth_weights.reference_depth,
      params_.icp.min_eigenvalue_ratio);
  step.degenerate = geometry.degeneracy.degenerate;
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  if (!step.degenerate || params_.motion_prior <= 0) {
    return engine_.align(source_span, target_views, identity);
  }
  return engine_.align(
      source_span, target_views, identity,
      {identity, registration::motion_prior_information(geometry, params_.motion_prior)});
}

std::size_t ModelTracker::evict_least_recently_seen(const Eigen::Isometry3d& camera_to_world) {
  const TsdfBlocks all = volume_.download();
  const std::vector<std::uint32_t> touched = volume_.last_touched();
  const double block_metres = kTsdfBlockSide * volume_.params().voxel_size;
  std::vector<double> distance(all.size());
  for (std::size_t b = 0; b < all.size(); ++b) {
    const Eigen::Vector3d centre = (all.coords[b].cast<double>().array() + 0.5) * block_metres;
    distance[b] = (centre - camera_to_world.translation()).norm();
  }
  // The most recently seen first; among those seen last together, the nearest.
  std::vector<std::size_t> order(all.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return touched[a] != touched[b] ? touched[a] > touched[b] : distance[a] < distance[b];
  });
  const auto half = static_cast<std::size_t>(0.5 * params_.evict_fill *
                                             static_cast<double>(volume_.params().max_blocks));
  order.resize(std::min(order.size(), half));
  std::sort(order.begin(), order.end());  // download()'s order
  TsdfBlocks kept;
  kept.voxel_size = all.voxel_size;
  kept.truncation = all.truncation;
  std::vector<std::uint32_t> kept_touched;
  for (const std::size_t b : order) {
    kept.coords.push_back(all.coords[b]);
    const auto first = all.voxels.begin() + static_cast<std::ptrdiff_t>(b * kTsdfBlockVoxels);
    kept.voxels.insert(kept.voxels.end(), first, first + kTsdfBlockVoxels);
    kept_touched.push_back(touched[b]);
  }
  volume_.assign(kept, kept_touched);
  return all.size() - kept.size();
}

ModelTrackingStep ModelTracker::track(const DepthImage& depth, const RgbImage* color,
                                      const Eigen::Isometry3d& predicted,
                                      const registration::FramePyramid* pyramid) {
  static const RgbImage kNoColor;
  frame_.upload(depth, color ? *color : kNoColor);
  ModelTrackingStep step;
  step.pose = predicted;
  if (empty_) {
    step.reason = "first frame";
  } else {
    const registration::IcpResult result = register_frame(source_pyramid(pyramid), predicted, step);
    step.fitness = result.fitness;
    step.inlier_rmse_m = result.inlier_rmse;
    step.reason = rejection(result);
    step.from_model = step.reason.empty();
    if (step.from_model) step.pose = predicted * result.source_to_target;
  }
  const auto full = static_cast<std::size_t>(params_.evict_fill *
                                             static_cast<double>(volume_.params().max_blocks));
  if (volume_.block_count() >= full) step.evicted_blocks = evict_least_recently_seen(step.pose);
  volume_.integrate(frame_.depth(), frame_.colors(), camera_, range_, step.pose);
  empty_ = false;
  return step;
}

}  // namespace kartograf::mapping
