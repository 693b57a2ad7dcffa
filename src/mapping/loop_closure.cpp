#include "kartograf/mapping/loop_closure.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>

#include "kartograf/geometry/pixel_projection.hpp"
#include "kartograf/mapping/chain_covariance.hpp"
#include "kartograf/registration/depth_weighted_finder.hpp"
#include "kartograf/registration/geometric_information.hpp"
#include "kartograf/registration/projective_association.hpp"
#include "mapping/keyframe_archive.hpp"

namespace kartograf::mapping {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

registration::PyramidParams pyramid_params(const LoopClosureParams& params, int finest_level,
                                           int information_level) {
  registration::PyramidParams pyramid;
  pyramid.levels =
      std::max(finest_level + static_cast<int>(params.icp.levels.size()), information_level + 1);
  pyramid.first_normals_level = std::min(finest_level, information_level);
  return pyramid;
}

void validate(const LoopClosureParams& p) {
  require(p.max_distance >= 0 && p.drift_fraction >= 0 && p.depth_tolerance > 0 &&
              p.min_correction_m >= 0,
          "loop closure: distances and fractions must be >= 0 (depth_tolerance > 0)");
  require(p.max_view_angle_deg >= 0 && p.max_view_angle_deg <= 180,
          "loop closure: max_view_angle_deg must be in [0, 180]");
  require(p.sample_step >= 1, "loop closure: sample_step must be >= 1");
  require(p.baseline_error_fraction >= 0, "loop closure: baseline_error_fraction must be >= 0");
  require(p.weak_direction_ratio >= 0 && p.weak_direction_ratio < 1,
          "loop closure: weak_direction_ratio must be in [0, 1)");
  require(p.feature_agreement_m > 0, "loop closure: feature_agreement_m must be > 0");
  require(p.icp_width > 0 && p.information_width > 0 && p.min_icp_level >= 0,
          "loop closure: icp_width and information_width must be > 0, min_icp_level >= 0");
  require(p.min_overlap >= 0 && p.min_overlap <= 1, "loop closure: min_overlap must be in [0, 1]");
}

// Angle between the optical axes (camera z) of two camera-to-world poses.
double view_angle_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const double cosine = std::clamp(a.linear().col(2).dot(b.linear().col(2)), -1.0, 1.0);
  return std::acos(cosine) / kDegree;
}

}  // namespace

std::string_view to_string(FeatureConfirmation confirmation) {
  switch (confirmation) {
    case FeatureConfirmation::not_asked:
      return "not_asked";
    case FeatureConfirmation::agree:
      return "agree";
    case FeatureConfirmation::disagree:
      return "disagree";
    case FeatureConfirmation::silent:
      return "silent";
    case FeatureConfirmation::no_features:
      return "no_features";
  }
  return "unknown";
}

registration::IcpParams loop_closure_icp_params() {
  registration::IcpParams params;
  params.metric = registration::ErrorMetric::point_to_plane;
  params.robust_kernel = registration::RobustKernel::huber;
  params.max_normal_angle_deg = 45;  // as odometry_icp_params()
  // Views from farther apart see fewer surface orientations; 0.01 rejects good loops.
  params.min_eigenvalue_ratio = 0.005;
  //      iterations, 1-in-k, max distance, robust scale
  params.levels = {
      {10, 2, 0.03, 0.01}, {10, 2, 0.10, 0.03}, {10, 1, 0.25, 0.08}, {15, 1, 0.50, 0.20}};
  return params;
}

LoopClosureDetector::LoopClosureDetector(
    const compute::Context& context, const PinholeIntrinsics& camera,
    const geometry::DepthRange& range, LoopClosureParams params,
    std::shared_ptr<const registration::FeatureFrontEnd> features)
    : camera_(camera),
      range_(range),
      params_(std::move(params)),
      finest_level_(std::max(
          params_.min_icp_level,
          registration::pyramid_level_at_most(camera.width, std::max(params_.icp_width, 1)))),
      information_level_(registration::pyramid_level_at_most(
          camera.width, std::max(params_.information_width, 1))),
      features_(std::move(features)),
      places_(features_ ? features_->make_place_index() : nullptr),
      builder_(context, camera, range),
      engine_(context, params_.icp,
              std::make_unique<registration::DepthWeightedFinder>(
                  context, std::make_unique<registration::ProjectiveAssociation>(context),
                  params_.depth_weights)),
      source_(context, camera, pyramid_params(params_, finest_level_, information_level_)),
      target_(context, camera, pyramid_params(params_, finest_level_, information_level_)) {
  validate(params_);
  depths_ =
      std::make_unique<FrameStore>(camera, range.units_per_metre, 1, params_.keyframe_depth_memory);
  archive_ = std::make_unique<KeyframeArchive>(features_, params_.keyframe_feature_memory);
}

LoopClosureDetector::~LoopClosureDetector() = default;

std::size_t LoopClosureDetector::keyframe_bytes_in_memory() const {
  return depths_->bytes_in_memory() + archive_->bytes_in_memory();
}

std::size_t LoopClosureDetector::keyframe_bytes_on_disk() const {
  return depths_->bytes_on_disk() + archive_->bytes_on_disk();
}

void LoopClosureDetector::add_keyframe(std::size_t frame, const DepthImage& depth,
                                       double path_length, const RgbImage* color) {
  require(keyframes_.empty() || frame > keyframes_.back().frame,
          "loop closure: keyframe " + std::to_string(frame) + " added after frame " +
              std::to_string(keyframes_.empty() ? 0 : keyframes_.back().frame));
  require(
      depth.width() == camera_.width && depth.height() == camera_.height,
      "loop closure: keyframe " + std::to_string(frame) + " depth size differs from the camera");
  KeyframeArchive::Entry entry;
  if (features_ && color && !color->empty()) {
    entry.features = features_->describe(depth, *color, camera_, range_.units_per_metre);
    places_->add(frame, *entry.features);
  }
  const int step = params_.sample_step;
  const double metres_per_unit = 1.0 / range_.units_per_metre;
  for (int v = step / 2; v < depth.height(); v += step) {
    for (int u = step / 2; u < depth.width(); u += step) {
      const double z = depth(u, v) * metres_per_unit;
      if (depth(u, v) == 0 || z < range_.min_metres || z > range_.max_metres) continue;
      entry.samples.emplace_back(static_cast<float>((u - camera_.cx) * z / camera_.fx),
                                 static_cast<float>((v - camera_.cy) * z / camera_.fy),
                                 static_cast<float>(z));
    }
  }
  depths_->add({depth, RgbImage(), 0.0, std::nullopt});
  keyframes_.push_back({frame, path_length});
  archive_->add(std::move(entry));
}

void LoopClosureDetector::require_pose(std::span<const Eigen::Isometry3d> poses,
                                       std::size_t frame) {
  require(frame < poses.size(), "loop closure: no pose for frame " + std::to_string(frame) + " (" +
                                    std::to_string(poses.size()) + " poses given)");
}

double LoopClosureDetector::view_overlap(std::size_t from, std::size_t to,
                                         const Eigen::Isometry3d& from_to_to,
                                         double tolerance) const {
  const std::shared_ptr<const KeyframeArchive::Entry> source = archive_->at(from);
  if (source->samples.empty()) return 0;
  const DepthImage target = depth_of(to);
  const double metres_per_unit = 1.0 / range_.units_per_metre;
  std::size_t seen = 0;
  for (const Eigen::Vector3f& sample : source->samples) {
    const Eigen::Vector3d p = from_to_to * sample.cast<double>();
    const std::optional<Eigen::Vector2i> pixel = geometry::nearest_pixel(camera_, p);
    if (!pixel) continue;
    const std::uint16_t d = target(pixel->x(), pixel->y());
    if (d != 0 && std::abs(d * metres_per_unit - p.z()) <= tolerance) ++seen;
  }
  return static_cast<double>(seen) / static_cast<double>(source->samples.size());
}

LoopCandidate LoopClosureDetector::candidate_between(
    std::size_t query, std::size_t match, std::span<const Eigen::Isometry3d> poses) const {
  const Keyframe& j = keyframes_.at(query);
  const Keyframe& i = keyframes_.at(match);
  require_pose(poses, j.frame);
  require_pose(poses, i.frame);
  const Eigen::Isometry3d& pose_i = poses[i.frame];
  const Eigen::Isometry3d& pose_j = poses[j.frame];
  LoopCandidate c;
  c.query = query;
  c.match = match;
  c.query_frame = j.frame;
  c.match_frame = i.frame;
  c.drift_allowance_m = params_.drift_fraction * std::max(0.0, j.path_length - i.path_length);
  c.distance_m = (pose_j.translation() - pose_i.translation()).norm();
  c.view_angle_deg = view_angle_deg(pose_i, pose_j);
  return c;
}

std::vector<LoopCandidate> LoopClosureDetector::find_candidates(
    std::size_t query, std::span<const Eigen::Isometry3d> poses) const {
  const Keyframe& j = keyframes_.at(query);
  std::vector<LoopCandidate> candidates;
  for (std::size_t match = 0; match < query; ++match) {
    if (j.frame - keyframes_[match].frame < params_.min_frame_gap) continue;
    LoopCandidate c = candidate_between(query, match, poses);
    if (c.distance_m > params_.max_distance + c.drift_allowance_m) continue;
    if (c.view_angle_deg > params_.max_view_angle_deg) continue;
    c.overlap = view_overlap(query, match, poses[c.match_frame].inverse() * poses[c.query_frame],
                             params_.depth_tolerance + c.drift_allowance_m);
    if (c.overlap < params_.min_overlap) continue;
    candidates.push_back(c);
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const LoopCandidate& a, const LoopCandidate& b) { return a.overlap > b.overlap; });
  if (candidates.size() > params_.max_candidates) candidates.resize(params_.max_candidates);
  return candidates;
}

std::vector<LoopCandidate> LoopClosureDetector::find_appearance_candidates(
    std::size_t query, std::span<const Eigen::Isometry3d> poses, bool relocalise) const {
  std::vector<LoopCandidate> candidates;
  const Keyframe& j = keyframes_.at(query);
  const std::size_t gap = relocalise ? 1 : params_.min_frame_gap;
  if (!places_ || !archive_->has_features(query) || j.frame < gap) return candidates;
  const std::shared_ptr<const registration::FeatureDescription> features =
      archive_->at(query)->features;
  const std::vector<registration::PlaceMatch> similar =
      places_->query(*features, j.frame - gap + 1, params_.max_appearance_candidates);
  for (const registration::PlaceMatch& place : similar) {
    // Places are keyframes' frame indices, in increasing order.
    const auto earlier = keyframes_.begin() + static_cast<std::ptrdiff_t>(query);
    const auto found =
        std::lower_bound(keyframes_.begin(), earlier, place.place,
                         [](const Keyframe& k, std::size_t frame) { return k.frame < frame; });
    if (found == earlier || found->frame != place.place) continue;
    const auto match = static_cast<std::size_t>(found - keyframes_.begin());
    if (!archive_->has_features(match)) continue;
    const std::optional<registration::FeatureAlignment> aligned =
        features_->align(*features, *archive_->at(match)->features);
    if (!aligned) continue;
    LoopCandidate c = candidate_between(query, match, poses);
    // Buildings repeat their materials and furniture: a look-alike elsewhere is only believed
    // where the estimate, with its drift allowance, could still be that wrong, or where so many
    // features agree that no look-alike has matched as well.
    const Eigen::Isometry3d estimated = poses[c.match_frame].inverse() * poses[c.query_frame];
    const double disagreement =
        (estimated.translation() - aligned->source_to_target.translation()).norm();
    if (disagreement > params_.max_distance + c.drift_allowance_m &&
        aligned->inliers < params_.decisive_feature_inliers)
      continue;
    c.by_appearance = true;
    c.feature_motion = aligned->source_to_target;
    c.feature_inliers = aligned->inliers;
    c.appearance_score = place.score;
    c.overlap = view_overlap(query, c.match, c.feature_motion, params_.depth_tolerance);
    candidates.push_back(c);
  }
  return candidates;
}

LoopClosure LoopClosureDetector::verify(const LoopCandidate& candidate,
                                        std::span<const Eigen::Isometry3d> poses,
                                        const ExpectedUncertainty& expected_uncertainty) {
  const Keyframe& query = keyframes_.at(candidate.query);
  const Keyframe& match = keyframes_.at(candidate.match);
  require_pose(poses, query.frame);
  require_pose(poses, match.frame);
  builder_.build(depth_of(candidate.query), nullptr, source_);
  builder_.build(depth_of(candidate.match), nullptr, target_);
  const Eigen::Isometry3d expected = candidate.by_appearance
                                         ? candidate.feature_motion
                                         : poses[match.frame].inverse() * poses[query.frame];
  const registration::IcpResult result = align(expected);
  const registration::GeometricInformation geometry = registration::geometric_information(
      source_.level(information_level_).view(), params_.depth_weights.reference_depth,
      params_.icp.min_eigenvalue_ratio);

  registration::RegistrationLimits limits = params_.verification;
  // The features' motion does not drift: only the pose estimate's allowance grows with the path.
  limits.max_correction_m =
      params_.min_correction_m + (candidate.by_appearance ? 0.0 : candidate.drift_allowance_m);
  LoopClosure closure;
  closure.candidate = candidate;
  closure.report = registration::judge_registration(result, expected, limits, geometry.degeneracy);
  // Where the query's geometry barely constrains a direction (along a corridor, along the line
  // where a wall meets the floor), ICP slides to answers that fit as well as the right one (on
  // the synthetic surveys 5-23 cm off the truth with fitness 0.5-0.8): the loop keeps the expected
  // motion in those directions and tells the graph nothing about them.
  const double weak = params_.weak_direction_ratio;
  const std::size_t free = weak > 0 ? registration::weak_directions(geometry, weak).size() : 0;
  closure.free_directions = free;
  if (needs_confirmation(closure))
    confirm_correction(closure, expected, result.source_to_target, expected_uncertainty);
  const Eigen::Isometry3d motion = free == 0
                                       ? result.source_to_target
                                       : registration::keep_constrained_directions(
                                             result.source_to_target, expected, geometry, weak);
  const se3::Matrix6d measured =
      free == 0 ? geometry.information : registration::constrained_information(geometry, weak);
  const double fraction = params_.baseline_error_fraction;
  const se3::Matrix6d information = registration::with_added_error(
      registration::edge_information(measured, result.inlier_rmse, params_.information),
      fraction * Eigen::AngleAxisd(motion.rotation()).angle(),
      fraction * motion.translation().norm());
  closure.constraint = {match.frame, query.frame, motion, information, false};
  return closure;
}

bool LoopClosureDetector::needs_confirmation(const LoopClosure& closure) const {
  if (!closure.report.accepted() || closure.candidate.by_appearance) return false;
  if (closure.report.correction_m > params_.min_correction_m) return true;
  return closure.free_directions == 0 &&
         closure.report.eigenvalue_ratio < 2 * params_.weak_direction_ratio;
}

FeatureConfirmation LoopClosureDetector::confirm_by_features(
    std::size_t query, std::size_t match, const Eigen::Isometry3d& motion) const {
  if (!features_ || !archive_->has_features(query) || !archive_->has_features(match))
    return FeatureConfirmation::no_features;
  const std::optional<registration::FeatureAlignment> aligned =
      features_->align(*archive_->at(query)->features, *archive_->at(match)->features);
  if (!aligned) return FeatureConfirmation::silent;
  const double apart = (aligned->source_to_target.translation() - motion.translation()).norm();
  return apart <= params_.feature_agreement_m ? FeatureConfirmation::agree
                                              : FeatureConfirmation::disagree;
}

void LoopClosureDetector::confirm_correction(
    LoopClosure& closure, const Eigen::Isometry3d& expected, const Eigen::Isometry3d& motion,
    const ExpectedUncertainty& expected_uncertainty) const {
  const LoopCandidate& candidate = closure.candidate;
  closure.confirmation = confirm_by_features(candidate.query, candidate.match, motion);
  bool confirmed = closure.confirmation == FeatureConfirmation::agree ||
                   closure.confirmation == FeatureConfirmation::no_features;
  if (closure.confirmation == FeatureConfirmation::silent && expected_uncertainty) {
    // The loop's own error grows with its baseline (baseline_error_fraction).
    const double fraction = params_.baseline_error_fraction;
    const double sigma_m =
        std::max(params_.information.min_sigma, fraction * motion.translation().norm());
    const double sigma_rad = fraction * se3::rotation_angle(motion);
    se3::Matrix6d covariance = expected_uncertainty(candidate);
    se3::Vector6d added;
    added << Eigen::Vector3d::Constant(sigma_rad * sigma_rad),
        Eigen::Vector3d::Constant(sigma_m * sigma_m);
    covariance.diagonal() += added;
    closure.correction_chi2 = mahalanobis_squared(expected.inverse() * motion, covariance);
    confirmed = closure.correction_chi2 <= params_.max_correction_chi2;
  }
  if (!confirmed) closure.report.verdict = registration::RegistrationVerdict::unconfirmed;
}

registration::IcpResult LoopClosureDetector::align(const Eigen::Isometry3d& initial) {
  const auto first = static_cast<std::size_t>(finest_level_);
  const std::size_t levels = params_.icp.levels.size();
  const std::vector<registration::CloudView> source_views = source_.views();
  const std::vector<registration::CloudView> target_views = target_.views();
  return engine_.align(std::span(source_views).subspan(first, levels),
                       std::span(target_views).subspan(first, levels), initial);
}

}  // namespace kartograf::mapping
