#include "kartograf/mapping/model_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
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

registration::PyramidParams pyramid_params(int levels) {
  registration::PyramidParams p;
  p.levels = levels;
  return p;
}

}  // namespace

TsdfVolumeParams ModelTrackingParams::default_volume() {
  TsdfVolumeParams v;
  v.voxel_size = 0.02;
  v.truncation = 0.08;
  v.max_blocks = 1 << 16;
  return v;
}

void ModelTrackingParams::validate() const {
  volume.validate();
  require(icp_width > 0 && information_width > 0,
          "model tracking: icp_width and information_width must be > 0");
  require(motion_prior >= 0, "model tracking: motion_prior must be >= 0");
  require(min_fitness >= 0 && min_fitness <= 1, "model tracking: min_fitness must be in [0, 1]");
  require(max_correction_m > 0 && max_correction_deg > 0,
          "model tracking: the largest correction must be > 0");
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
      volume_(context, params.volume),
      projector_(context, camera, range_),
      target_camera_(level_camera(camera, first_level_)),
      source_(context, camera,
              pyramid_params(std::max(first_level_ + static_cast<int>(params.icp.levels.size()),
                                      information_level_ + 1))),
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

ModelTrackingStep ModelTracker::track(const DepthImage& depth, const RgbImage* color,
                                      const Eigen::Isometry3d& predicted) {
  static const RgbImage kNoColor;
  frame_.upload(depth, color ? *color : kNoColor);
  ModelTrackingStep step;
  step.pose = predicted;
  if (empty_) {
    step.reason = "first frame";
  } else {
    source_.build(projector_, frame_.depth());
    // Cast at ICP's first level only: the finer level would cost 4x and never be read.
    volume_.raycast(target_camera_, range_, predicted, target_.base_points());
    target_.build();
    const auto first = static_cast<std::size_t>(first_level_);
    const std::vector<registration::CloudView> source_views = source_.views();
    const std::vector<registration::CloudView> target_views = target_.views();
    const std::span<const registration::CloudView> source_span =
        std::span(source_views).subspan(first, params_.icp.levels.size());
    const registration::GeometricInformation geometry = registration::geometric_information(
        source_.level(information_level_).view(), params_.depth_weights.reference_depth,
        params_.icp.min_eigenvalue_ratio);
    step.degenerate = geometry.degeneracy.degenerate;
    const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
    const registration::IcpResult result =
        step.degenerate && params_.motion_prior > 0
            ? engine_.align(source_span, target_views, identity,
                            {identity, registration::motion_prior_information(
                                           geometry, params_.motion_prior)})
            : engine_.align(source_span, target_views, identity);
    step.fitness = result.fitness;
    step.inlier_rmse_m = result.inlier_rmse;
    step.reason = rejection(result);
    step.from_model = step.reason.empty();
    if (step.from_model) step.pose = predicted * result.source_to_target;
  }
  volume_.integrate(frame_.depth(), frame_.colors(), camera_, range_, step.pose);
  empty_ = false;
  return step;
}

}  // namespace kartograf::mapping
