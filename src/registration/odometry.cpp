#include "kartograf/registration/odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <numeric>
#include <span>
#include <string>
#include <utility>

#include "kartograf/core/memory_budget.hpp"
#include "kartograf/core/pose.hpp"
#include "kartograf/geometry/subsample.hpp"
#include "kartograf/registration/depth_weighted_finder.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kartograf/registration/projective_association.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/segmentation/plane_sampling.hpp"

namespace kartograf::registration {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

std::unique_ptr<CorrespondenceFinder> finder_for(const compute::Context& context,
                                                 const OdometryParams& params) {
  std::unique_ptr<CorrespondenceFinder> finder = std::make_unique<ProjectiveAssociation>(context);
  if (params.method == OdometryMethod::color) {
    finder = std::make_unique<ColorGatedFinder>(context, std::move(finder), params.color_gate);
  }
  if (!params.depth_weighting) return finder;
  return std::make_unique<DepthWeightedFinder>(context, std::move(finder), params.depth_weights);
}

// The photometric refinement moves the answer in directions ICP did not measure. Beyond the
// registration's correction limits its answer is kept only where the images fit it (a grey-level
// RMSE within `doubt_rmse`). Survey seed 4, frame 150 against 145: ICP 1 cm from the chain, the
// images 3.7 cm and 1.1 degrees on from it, pulled by what the 18 cm step occluded, at an RMSE of
// 15 (25 before). Survey seed 8, frame 710 against 705: 4.2 cm from the chain, mending a turn's
// onset that the chain missed, at an RMSE of 1.7 (6.3 before).
bool keeps_refinement(const Eigen::Isometry3d& expected, const PhotometricResult& refined,
                      const RegistrationLimits& limits, double doubt_rmse) {
  if (!refined.refined) return false;
  return within_limits(correction_of(expected, refined.motion), limits) ||
         refined.rmse_after <= doubt_rmse;
}

PyramidParams pyramid_params(const OdometryParams& params, int finest_level,
                             int information_level) {
  PyramidParams pyramid;
  pyramid.levels =
      std::max(finest_level + static_cast<int>(params.icp.levels.size()), information_level + 1);
  pyramid.with_colors = params.method == OdometryMethod::color;
  pyramid.first_normals_level = std::min(finest_level, information_level);
  return pyramid;
}

void validate(const OdometryParams& params) {
  require(params.reestimate_interval >= 0, "odometry: reestimate_interval must be >= 0");
  require(params.icp_width > 0 && params.information_width > 0 && params.min_icp_level >= 0,
          "odometry: icp_width and information_width must be > 0, min_icp_level >= 0");
  require(params.motion_prior >= 0 && params.motion_prior_translation >= 0,
          "odometry: motion_prior and motion_prior_translation must be >= 0");
  require(params.recheck_correction_m > 0, "odometry: recheck_correction_m must be > 0");
  require(params.recheck_fitness >= 0 && params.recheck_fitness <= 1,
          "odometry: recheck_fitness must be in [0, 1]");
  require(params.feature_seed_m >= 0 && params.feature_seed_deg >= 0,
          "odometry: feature_seed_m and feature_seed_deg must be >= 0");
  require(params.feature_arbitration_m >= 0 && params.feature_arbitration_deg >= 0 &&
              params.feature_arbitration_ratio > 0 && params.photometric_doubt_rmse > 0,
          "odometry: feature_arbitration_m and _deg must be >= 0, feature_arbitration_ratio and "
          "photometric_doubt_rmse > 0");
  require(params.speed_change_margin >= 0, "odometry: speed_change_margin must be >= 0");
  require(params.keyframes.max_interval >= 1, "odometry: keyframes.max_interval must be >= 1");
  require(params.anchor.max_translation >= 0 && params.anchor.max_rotation_deg >= 0 &&
              params.anchor.max_interval >= 0,
          "odometry: the anchor policy's bounds must be >= 0");
  require(params.fallback_sigma_m > 0 && params.fallback_sigma_deg > 0,
          "odometry: fallback standard deviations must be > 0");
  require(params.information.effective_pairs > 0 && params.information.min_sigma > 0,
          "odometry: information model values must be > 0");
  params.depth_noise_gate.validate();
  require(std::isfinite(params.photometric_deep_weight) && params.photometric_deep_weight >= 0,
          "odometry: photometric_deep_weight must be finite and >= 0");
  require(std::isfinite(params.contradiction_weight) && params.contradiction_weight >= 0 &&
              params.contradiction_floor >= 0 && params.contradiction_floor <= 1,
          "odometry: contradiction_weight must be finite and >= 0, contradiction_floor in [0, 1]");
  params.colour_registration.validate();
}

// Composing poses (and inverting them by transposition, as Isometry3d does) lets rounding errors
// in the rotation grow from one re-estimate to the next; project back onto SO(3) after each.
Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& pose) {
  Eigen::Isometry3d result = pose;
  result.linear() = Eigen::Quaterniond(pose.linear()).normalized().toRotationMatrix();
  return result;
}

// The motion's step with no turn: a start for ICP where the turn may be wrong.
Eigen::Isometry3d without_its_turn(const Eigen::Isometry3d& motion) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation() = motion.translation();
  return step;
}

bool is_identity(const Eigen::Isometry3d& pose) {
  return pose.matrix().isApprox(Eigen::Matrix4d::Identity(), 1e-12);
}

}  // namespace

std::string_view to_string(StepFrame frame) {
  switch (frame) {
    case StepFrame::world:
      return "world";
    case StepFrame::camera:
      return "camera";
    case StepFrame::arc:
      return "arc";
    case StepFrame::adaptive:
      return "adaptive";
  }
  return "unknown";
}

OdometryMethod parse_odometry_method(std::string_view name, std::string_view what) {
  if (name == "p2p") return OdometryMethod::point_to_point;
  if (name == "p2plane") return OdometryMethod::point_to_plane;
  if (name == "color") return OdometryMethod::color;
  if (name == "planar") return OdometryMethod::planar;
  throw Error(std::string(what) + ": '" + std::string(name) +
              "' is not an odometry method (p2p, p2plane, color, planar)");
}

IcpParams odometry_icp_params(OdometryMethod method) {
  IcpParams params;
  // 4-neighbour normals of Kinect-noisy depth scatter by tens of degrees: a 30 degree gate drops
  // most good pairs (fitness 0.25 on perfectly aligned synthetic frames), 45 keeps half of them.
  params.max_normal_angle_deg = 45;
  // Degenerate below 0.03 (balanced eigenvalue ratio of the geometric information): on 320x240
  // frames entering a room through a doorway towards a wall (ratio 0.018) ICP slid 5 cm along the
  // weak direction.
  params.min_eigenvalue_ratio = 0.03;
  // On pyramid levels 1..3 (320x240 down to 80x60 for 640x480 frames): 1 point in 2 at 320x240
  // is as accurate as all of them (synthetic tour: 0.45 mm and 0.009 deg per frame) at half the
  // cost. The coarse gate is wide for 30 Hz motions of up to ~8 cm and 5 degrees.
  //      iterations, 1-in-k, max distance, robust scale
  params.levels = {{6, 2, 0.03, 0.01}, {6, 2, 0.10, 0.03}, {10, 1, 0.30, 0.10}};
  switch (method) {
    case OdometryMethod::point_to_plane:
    case OdometryMethod::color:
      params.metric = ErrorMetric::point_to_plane;
      break;
    case OdometryMethod::planar:
      // One level on the plane samples (a few thousand points with exact plane normals, ~5 cm
      // apart): k-d tree pairs within 10 cm whose normals agree within 30 degrees.
      params.metric = ErrorMetric::point_to_plane;
      params.max_normal_angle_deg = 30;
      params.levels = {{30, 1, 0.10, 0.03}};
      break;
    case OdometryMethod::point_to_point:
      // Point-to-point converges linearly and needs the closest point, not the projected one
      // (icp.hpp): more iterations and a search window.
      params.metric = ErrorMetric::point_to_point;
      params.levels = {{20, 2, 0.03, 0.01, 1}, {15, 2, 0.10, 0.03, 1}, {15, 1, 0.30, 0.10, 1}};
      break;
  }
  return params;
}

struct RgbdOdometry::PlanarFrames {
  PlanarFrames(const compute::Context& context, const PinholeIntrinsics& camera,
               const IcpParams& icp, std::size_t slots)
      : extractor(context, camera),
        engine(context, icp, std::make_unique<KdTreeCorrespondences>(context)),
        samples(slots) {}

  segmentation::PlaneExtractor extractor;
  IcpEngine engine;
  std::vector<geometry::DeviceCloud> samples;  // per frame slot
};

RgbdOdometry::~RgbdOdometry() = default;
RgbdOdometry::RgbdOdometry(RgbdOdometry&&) noexcept = default;
RgbdOdometry& RgbdOdometry::operator=(RgbdOdometry&&) noexcept = default;

RgbdOdometry::RgbdOdometry(const compute::Context& context, const PinholeIntrinsics& camera,
                           OdometryParams params)
    : context_(&context),
      params_(std::move(params)),
      finest_level_(std::max(params_.min_icp_level,
                             pyramid_level_at_most(camera.width, std::max(params_.icp_width, 1)))),
      information_level_(
          pyramid_level_at_most(camera.width, std::max(params_.information_width, 1))),
      builder_(context, camera, params_.depth_range),
      engine_(context, params_.icp, finder_for(context, params_)),
      speed_bound_(params_.speed_change_margin, params_.feature_arbitration_m) {
  validate(params_);
  colour_check_ = ColourRegistrationCheck(params_.colour_registration);
  // The frame being tracked, the previous one and, with re-estimation, the anchor: whatever k and
  // the anchor policy, no other frame is registered against again.
  const std::size_t slots = params_.reestimate_interval > 0 ? 3 : 2;
  // Per pixel and slot: points, normals and packed colours over the pyramid's levels (4/3 of the
  // finest), and the colour kept for photometric refinement.
  const double pixel_bytes = (2 * sizeof(Point4f) + sizeof(std::uint32_t)) * 4.0 / 3 + sizeof(Rgb8);
  require_fits_in_memory(pixel_bytes * slots * camera.width * camera.height,
                         "odometry: " + std::to_string(slots) + " frame pyramids of " +
                             std::to_string(camera.width) + " x " + std::to_string(camera.height) +
                             " pixels");
  slot_frames_.assign(slots, kNoFrame);
  ring_.reserve(slots);
  for (std::size_t i = 0; i < slots; ++i)
    ring_.emplace_back(context, camera, pyramid_params(params_, finest_level_, information_level_));
  images_.resize(slots);
  if (params_.method == OdometryMethod::planar) {
    require(params_.points_per_plane > 0, "odometry: points_per_plane must be > 0");
    planar_ = std::make_unique<PlanarFrames>(context, camera, params_.icp, slots);
  }
}

std::size_t RgbdOdometry::slot_of(std::size_t frame) const {
  const auto found = std::find(slot_frames_.begin(), slot_frames_.end(), frame);
  require(found != slot_frames_.end(),
          "odometry: frame " + std::to_string(frame) + " is no longer kept (internal error)");
  return static_cast<std::size_t>(found - slot_frames_.begin());
}

std::size_t RgbdOdometry::claim_slot(std::size_t frame) {
  // Keep frame-1 (the next frame's previous) and the anchor of the next re-estimate.
  const std::size_t previous = frame == 0 ? kNoFrame : frame - 1;
  const std::size_t anchor = (params_.reestimate_interval > 0 && frame > 0) ? anchor_ : kNoFrame;
  for (std::size_t slot = 0; slot < slot_frames_.size(); ++slot) {
    const std::size_t held = slot_frames_[slot];
    if (held == kNoFrame || (held != previous && held != anchor)) {
      slot_frames_[slot] = frame;
      return slot;
    }
  }
  throw Error("odometry: no free frame slot (internal error)");
}

FramePyramid& RgbdOdometry::pyramid_of(std::size_t frame) {
  return ring_[slot_of(frame)];
}

const FramePyramid& RgbdOdometry::latest_pyramid() const {
  require(!poses_.empty(), "odometry: no frame tracked yet, so no latest pyramid");
  return ring_[slot_of(poses_.size() - 1)];
}

RgbdOdometry::Attempt RgbdOdometry::register_frames(std::size_t target,
                                                    const Eigen::Isometry3d& initial,
                                                    const RegistrationLimits& limits) {
  const std::size_t current = frames_.size();  // frames_ grows when track() ends
  std::span<const CloudView> source_views;
  std::span<const CloudView> target_views;
  std::vector<CloudView> source_levels;
  std::vector<CloudView> target_levels;
  IcpEngine* engine = &engine_;
  if (planar_) {
    const auto view = [](const geometry::DeviceCloud& cloud) {
      return CloudView{&cloud.points, &cloud.normals, nullptr, std::nullopt};
    };
    source_levels = {view(planar_->samples[slot_of(current)])};
    target_levels = {view(planar_->samples[slot_of(target)])};
    source_views = source_levels;
    target_views = target_levels;
    engine = &planar_->engine;
  } else {
    const auto first = static_cast<std::size_t>(finest_level_);
    const std::size_t count = params_.icp.levels.size();
    source_levels = pyramid_of(current).views();
    target_levels = pyramid_of(target).views();
    source_views = std::span<const CloudView>(source_levels).subspan(first, count);
    target_views = std::span<const CloudView>(target_levels).subspan(first, count);
  }
  // Degenerate views: the motion model, as a prior, decides the weak directions while ICP
  // solves; the other frames solve the pairs' system alone.
  const MotionPriorStrength prior = motion_prior_for(target + 1 == current, initial);
  const IcpResult result =
      geometry_.degeneracy.degenerate && params_.motion_prior > 0
          ? engine->align(source_views, target_views, initial,
                          {initial, motion_prior_information(geometry_, prior)})
          : engine->align(source_views, target_views, initial);
  Attempt attempt;
  attempt.report = judge_registration(result, initial, limits, geometry_.degeneracy);
  attempt.inlier_rmse = result.inlier_rmse;
  attempt.motion = result.source_to_target;
  measure_deep_view(attempt, current, target, initial, limits);
  if (!attempt.report.accepted() || !geometry_.degeneracy.degenerate) return attempt;
  // A step from the frame before: a robot's sideways slide comes from its heading.
  if (target + 1 == current) hold_across_heading(attempt, prior);
  // What the geometry cannot tell comes from the initial guess (the motion model)...
  const double ratio = params_.icp.min_eigenvalue_ratio;
  if (params_.motion_prior == 0) {
    attempt.motion =
        keep_constrained_directions(result.source_to_target, initial, geometry_, ratio);
  }
  // ...or from the images, when there are colours.
  const PhotometricFrame& source_images = images_[slot_of(current)];
  const PhotometricFrame& target_images = images_[slot_of(target)];
  if (!source_images.empty() && !target_images.empty()) {
    // Ascending eigenvalues: the degenerate directions come first, and the images must measure
    // those; the barely constrained ones after them are held by what ICP measured.
    const std::vector<se3::Vector6d> directions =
        weak_directions(geometry_, std::max(ratio, params_.photometric_direction_ratio));
    const std::size_t degenerate = weak_directions(geometry_, ratio).size();
    const double pairs =
        params_.photometric_geometry_weight * static_cast<double>(geometry_.points);
    const se3::Matrix6d held =
        edge_information(constrained_information(geometry_, ratio), attempt.inlier_rmse,
                         {pairs, params_.information.min_sigma}) +
        attempt.across_heading;
    const PhotometricResult refined =
        refine_photometrically(source_images, target_images, builder_.camera(), attempt.motion,
                               directions, params_.photometric, held, degenerate);
    attempt.photometric_rmse = refined.rmse_before;
    attempt.refined_rmse = refined.rmse_after;
    if (keeps_refinement(initial, refined, limits, params_.photometric_doubt_rmse)) {
      attempt.motion = refined.motion;
      attempt.photometric = true;
      attempt.photometric_rmse = refined.rmse_after;
      // A faint texture's sigma (thousands of pixels at the noise's level: 0.01 mm) claims more
      // than it measures; the pose graph leaves such a step's free directions to the loops.
      attempt.photometric_sigma_m = refined.faint ? 0.0 : refined.sigma_m;
      measure_travel_length(attempt, initial, limits, source_images, target_images);
    }
  }
  return attempt;
}

void RgbdOdometry::measure_deep_view(Attempt& attempt, std::size_t current, std::size_t target,
                                     const Eigen::Isometry3d& initial,
                                     const RegistrationLimits& limits) const {
  // Deep: the depth noise widened ICP's finest gate for this frame (set_finest_gate).
  const bool deep =
      !planar_ && engine_.params().levels[0].max_distance > params_.icp.levels[0].max_distance;
  if (!attempt.report.accepted() || geometry_.degeneracy.degenerate ||
      params_.photometric_deep_weight <= 0 || !deep ||
      colour_check_.verdict() != ColourRegistration::registered)
    return;
  const PhotometricFrame& source = images_[slot_of(current)];
  const PhotometricFrame& onto = images_[slot_of(target)];
  if (source.empty() || onto.empty()) return;
  // All six directions; ICP's answer holds them by what it measured.
  const std::vector<se3::Vector6d> directions = weak_directions(geometry_, 2.0);
  const double pairs = params_.photometric_deep_weight * static_cast<double>(geometry_.points);
  const se3::Matrix6d held =
      edge_information(constrained_information(geometry_, params_.icp.min_eigenvalue_ratio),
                       attempt.inlier_rmse, {pairs, params_.information.min_sigma});
  const PhotometricResult refined = refine_photometrically(
      source, onto, builder_.camera(), attempt.motion, directions, params_.photometric, held, 0);
  if (!keeps_refinement(initial, refined, limits, params_.photometric_doubt_rmse)) return;
  attempt.motion = refined.motion;
  attempt.deep_photometric = true;
}

void RgbdOdometry::measure_travel_length(Attempt& attempt, const Eigen::Isometry3d& initial,
                                         const RegistrationLimits& limits,
                                         const PhotometricFrame& source,
                                         const PhotometricFrame& target) const {
  if (!params_.photometric_travel_length || attempt.heading_sigma_m <= 0 ||
      is_large(attempt.motion))
    return;
  const Eigen::Vector3d travel = heading_prior_.travel_on(attempt.motion);
  // The length along the travel (target frame) is a translation of the source along R^T travel.
  se3::Vector6d along = se3::Vector6d::Zero();
  along.tail<3>() = (attempt.motion.linear().transpose() * travel).normalized();
  if (translation_constraint(geometry_, along.tail<3>()) > params_.photometric_direction_ratio)
    return;
  const PhotometricResult length =
      refine_photometrically(source, target, builder_.camera(), attempt.motion,
                             std::span<const se3::Vector6d>(&along, 1), params_.photometric);
  if (!keeps_refinement(initial, length, limits, params_.photometric_doubt_rmse) ||
      length.rmse_after > params_.photometric_travel_max_rmse)
    return;
  attempt.motion = length.motion;
  attempt.photometric_rmse = length.rmse_after;
  attempt.refined_rmse = length.rmse_after;
}

se3::Matrix6d RgbdOdometry::information_of(const Attempt& attempt) const {
  // Degenerate without a photometric measurement: the weak directions are the motion model's, so
  // only the prior speaks for them and a loop closure can move them at little cost. Where the
  // heading prior held the sideways slide, it holds it in the pose graph too (along the free
  // directions): a loop cannot pull a robot sideways there.
  const se3::Matrix6d measured =
      geometry_.degeneracy.degenerate && !attempt.photometric
          ? constrained_information(geometry_, params_.icp.min_eigenvalue_ratio)
          : geometry_.information;
  // In the pose graph only where it decided: the directions the geometry left free. Across the
  // heading in every direction, it also held the camera's tilt to the learned heading's, and loops
  // bent the trajectory's turns instead (survey seed 5: rotation error 0.14 -> 0.21 degrees).
  const std::vector<se3::Vector6d> free_directions =
      weak_directions(geometry_, params_.icp.min_eigenvalue_ratio);
  const se3::Matrix6d across_heading =
      attempt.heading_sigma_m > 0 ? information_along(attempt.across_heading, free_directions)
                                  : se3::Matrix6d::Zero();
  return edge_information(measured, attempt.inlier_rmse, params_.information) +
         prior_information(params_.fallback_sigma_deg * kDegree, params_.fallback_sigma_m) +
         across_heading + images_information(attempt, free_directions);
}

se3::Matrix6d RgbdOdometry::images_information(
    const Attempt& attempt, std::span<const se3::Vector6d> free_directions) const {
  const double sigma_m = params_.photometric_graph_sigma_factor * attempt.photometric_sigma_m;
  if (!geometry_.degeneracy.degenerate || !attempt.photometric || sigma_m <= 0)
    return se3::Matrix6d::Zero();
  // sigma_m is what the motion moves a point 2 m ahead: sigma_m / 2 radians of turn.
  return information_along(prior_information(sigma_m / 2.0, sigma_m), free_directions);
}

void RgbdOdometry::hold_across_heading(Attempt& attempt, const MotionPriorStrength& prior) const {
  if (!params_.heading_prior || !heading_prior_.ready()) return;
  // ICP's answer was already the minimum of the pairs and the motion model's prior: both weigh
  // against the heading's (a hand-held camera's wide spread leaves the motion model in charge).
  const se3::Matrix6d icp = geometry_.information + motion_prior_information(geometry_, prior);
  attempt.motion = heading_prior_.combine(
      attempt.motion, edge_information(icp, attempt.inlier_rmse, params_.information));
  attempt.across_heading = heading_prior_.information(attempt.motion);
  attempt.heading_sigma_m = std::sqrt(heading_prior_.across_variance());
}

const OdometryFrame& RgbdOdometry::track(const DepthImage& depth, const RgbImage* color,
                                         const std::optional<Eigen::Isometry3d>& motion_prior) {
  const auto start = std::chrono::steady_clock::now();
  OdometryFrame frame;
  frame.index = poses_.size();
  require(!motion_prior || is_rigid(*motion_prior),
          "odometry: frame " + std::to_string(frame.index) +
              ": its motion prior is not a finite rigid motion");
  prior_before_ = frame.index > 0 ? prior_now_ : std::nullopt;
  prior_now_ = motion_prior;
  const std::optional<Eigen::Isometry3d> prior_step = prior_motion();
  frame.from_motion_prior = prior_step.has_value();
  // Colour is read on the depth image's pixel grid (photometric refinement, planes).
  require(color == nullptr || color->empty() ||
              (color->width() == depth.width() && color->height() == depth.height()),
          "odometry: frame " + std::to_string(frame.index) + ": colour image is " +
              std::to_string(color ? color->width() : 0) + "x" +
              std::to_string(color ? color->height() : 0) + ", its depth image is " +
              std::to_string(depth.width()) + "x" + std::to_string(depth.height()));
  FramePyramid& pyramid = ring_[claim_slot(frame.index)];
  builder_.build(depth, color, pyramid);
  if (planar_) {
    require(color != nullptr && !color->empty(),
            "odometry: the planar method needs the colour image of every frame");
    const PointImage points =
        geometry::backproject(*context_, depth, builder_.camera(), params_.depth_range);
    const segmentation::PlaneSet planes = planar_->extractor.extract(points, *color);
    planar_->samples[slot_of(frame.index)] = geometry::DeviceCloud::from_host(
        *context_, segmentation::sample_plane_points(points, nullptr, planes,
                                                     {params_.points_per_plane, frame.index + 1}));
  }
  depth_ = &depth;
  color_ = color;
  // Prepared on first use: frames the refinement never compares cost a copy of their images.
  images_[slot_of(frame.index)] =
      params_.photometric_refinement && color && !color->empty()
          ? PhotometricFrame(*color, depth, params_.depth_range.units_per_metre)
          : PhotometricFrame();
  if (params_.photometric_deep_weight > 0 && !images_[slot_of(frame.index)].empty())
    colour_check_.add(depth, *color);
  frame.colour_registration = colour_check_.verdict();
  frame.colour_edge_contrast = colour_check_.contrast();
  geometry_ = level_geometry(pyramid.level(information_level_).view());
  set_finest_gate(depth);
  frame.degenerate = geometry_.degeneracy.degenerate;
  frame.eigenvalue_ratio = geometry_.degeneracy.eigenvalue_ratio;
  if (frame.index == 0) {
    poses_.push_back(Eigen::Isometry3d::Identity());
  } else {
    track_previous(frame);
    if (prior_step) record_prior_difference(*prior_step, frame);
    const auto k = static_cast<std::size_t>(params_.reestimate_interval);
    if (k > 0 && frame.index % k == 0) reestimate(frame);
  }
  frame.keyframe = is_keyframe(frame);
  if (frame.keyframe) keyframes_.push_back(frame.index);
  keep_images_for_features(depth, color);
  context_->finish();
  frame.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  depth_ = nullptr;
  color_ = nullptr;
  frames_.push_back(frame);
  return frames_.back();
}

void RgbdOdometry::set_finest_gate(const DepthImage& depth) {
  // Not the planar method's one level (plane samples), nor a degenerate view: there the motion
  // prior and the images decide the free directions, and a wider gate let ICP's floor slide
  // along a robot's step (the speed bound's and the step scan's test frames, 9.6 cm).
  if (planar_) return;
  double gate = params_.icp.levels[0].max_distance;
  if (!geometry_.degeneracy.degenerate) {
    gate = depth_noise_gate(
        gate,
        median_depth_m(depth, params_.depth_range.units_per_metre, params_.depth_noise_gate.stride),
        params_.depth_noise_gate);
  }
  engine_.set_max_distance(0, gate);
}

Eigen::Isometry3d RgbdOdometry::predict(StepFrame step_frame) const {
  return predict(step_frame, params_.motion_model);
}

void RgbdOdometry::record_prior_difference(const Eigen::Isometry3d& prior_step,
                                           OdometryFrame& frame) const {
  const std::size_t n = poses_.size() - 1;  // the frame just tracked
  const Eigen::Isometry3d off = prior_step.inverse() * (poses_[n - 1].inverse() * poses_[n]);
  frame.prior_difference_m = off.translation().norm();
  frame.prior_difference_deg = se3::rotation_angle(off) / kDegree;
}

std::optional<Eigen::Isometry3d> RgbdOdometry::prior_motion() const {
  // Only while the frame that came with prior_now_ is being tracked (afterwards poses_ has it).
  if (poses_.size() != frames_.size() || !prior_before_ || !prior_now_) return std::nullopt;
  return orthonormalized(prior_before_->inverse() * *prior_now_);
}

Eigen::Isometry3d RgbdOdometry::predict(StepFrame step_frame, MotionModel model) const {
  const std::size_t n = poses_.size();  // the frame to predict
  if (model == MotionModel::still) return Eigen::Isometry3d::Identity();
  // Another sensor's motion wins over every model (they are guesses from the frames before).
  if (const std::optional<Eigen::Isometry3d> prior = prior_motion()) return *prior;
  if (n < 2) return Eigen::Isometry3d::Identity();
  // Rotation: the last turn again, in the camera frame. Translation: the camera centre's last
  // step (with `acceleration`, changed as it changed before), in the world or the camera frame.
  const auto step_of = [&](std::size_t to) -> Eigen::Vector3d {
    const Eigen::Vector3d world = poses_[to].translation() - poses_[to - 1].translation();
    return step_frame != StepFrame::world
               ? Eigen::Vector3d(poses_[to - 1].linear().transpose() * world)
               : world;
  };
  Eigen::Vector3d step = step_of(n - 1);
  if (model == MotionModel::acceleration && n >= 3) step += step - step_of(n - 2);
  const Eigen::Isometry3d& last = poses_[n - 1];
  const Eigen::Isometry3d& before = poses_[n - 2];
  Eigen::Isometry3d predicted = Eigen::Isometry3d::Identity();
  predicted.linear() = before.linear().transpose() * last.linear();
  predicted.translation() =
      step_frame == StepFrame::world ? Eigen::Vector3d(last.linear().transpose() * step) : step;
  if (step_frame == StepFrame::arc && heading_prior_.heading().squaredNorm() > 0) {
    // A wheeled robot's step on an arc: its heading turned by half the turn, the last speed.
    predicted.translation() = step.norm() * heading_prior_.travel_on(predicted);
  }
  return orthonormalized(predicted);
}

StepFrame RgbdOdometry::step_frame_in_use() const {
  if (params_.step_frame != StepFrame::adaptive) return params_.step_frame;
  if (arc_step_error_ < camera_step_error_ && arc_step_error_ < world_step_error_) {
    return StepFrame::arc;
  }
  return camera_step_error_ < world_step_error_ ? StepFrame::camera : StepFrame::world;
}

void RgbdOdometry::score_step_frames(const Eigen::Isometry3d& measured) {
  // Over about the last 20 well-constrained frames.
  constexpr double kKeep = 0.95;
  const auto squared_error = [&](StepFrame frame) {
    return (predict(frame).translation() - measured.translation()).squaredNorm();
  };
  world_step_error_ = kKeep * world_step_error_ + (1 - kKeep) * squared_error(StepFrame::world);
  camera_step_error_ = kKeep * camera_step_error_ + (1 - kKeep) * squared_error(StepFrame::camera);
  arc_step_error_ = kKeep * arc_step_error_ + (1 - kKeep) * squared_error(StepFrame::arc);
  heading_prior_.learn(measured);
}

RegistrationLimits RgbdOdometry::frame_limits_now() const {
  RegistrationLimits limits = params_.frame_limits;
  if (params_.corrections_up_to_largest_step) {
    limits.max_correction_m = std::max(limits.max_correction_m, largest_step_m_);
  }
  return limits;
}

MotionPriorStrength RgbdOdometry::motion_prior_for(bool step_from_previous,
                                                   const Eigen::Isometry3d& initial) const {
  if (params_.motion_prior == 0) return {};  // off, the translations' too
  // A step's start may be large where its prediction was not: the features' motion at the
  // sequence's start, before the motion model knows the speed.
  const bool large = large_step_ || (step_from_previous && is_large(initial));
  return {params_.motion_prior, large ? params_.motion_prior : params_.motion_prior_translation};
}

bool RgbdOdometry::is_large(const Eigen::Isometry3d& motion) const {
  return motion.translation().norm() > params_.feature_seed_m ||
         se3::rotation_angle(motion) > params_.feature_seed_deg * kDegree;
}

RgbdOdometry::Attempt RgbdOdometry::attempt_previous(const Eigen::Isometry3d& predicted,
                                                     OdometryFrame& frame) {
  Attempt chosen = chosen_previous(predicted, frame);
  // However it was chosen (another start, the features), a step the images left open is measured.
  if (scans_along_heading() && !chosen.scanned && images_left_open(chosen)) {
    if (std::optional<Attempt> scanned = scan_along_heading(frame.step_frame, predicted, chosen))
      chosen = std::move(*scanned);
  }
  if (std::optional<Attempt> freed = scan_free_translations(chosen)) chosen = std::move(*freed);
  return chosen;
}

RgbdOdometry::Attempt RgbdOdometry::chosen_previous(const Eigen::Isometry3d& predicted,
                                                    OdometryFrame& frame) {
  const std::size_t previous = frame.index - 1;
  // A large predicted motion may be beyond ICP's basin: ICP from the features' motion as well,
  // kept unless the pair agrees better with ICP from the prediction (features matched on a
  // repeated texture, a tile or two over, or on too little; docs/slam.md). Other starts are not
  // weighed against the features: by fitness they picked wrong turns in rooms that look alike.
  std::optional<Attempt> seeded;
  if (is_large(predicted)) seeded = register_from_features();
  // On a degenerate view their step may be a tile over where their turn is right.
  if (seeded) seeded = features_turn_on_the_arc(frame.step_frame, predicted, std::move(*seeded));
  Attempt attempt = accelerating_if_better(
      frame.step_frame, predicted, register_frames(previous, predicted, frame_limits_now()));
  if (images_left_open(attempt)) {
    std::optional<Attempt> scanned = scans_along_heading()
                                         ? scan_along_heading(frame.step_frame, predicted, attempt)
                                         : scan_step_lengths(frame.step_frame, predicted, attempt);
    if (scanned) attempt = std::move(*scanned);
  }
  // A large motion on a constrained view: a settled answer may still be a neighbouring basin's.
  const bool recheck_large =
      params_.recheck_large_motions && is_large(predicted) && !geometry_.degeneracy.degenerate;
  if (seeded) {
    if (keeps_prediction(attempt, *seeded)) {
      if (params_.recheck_after_features && (is_doubtful(attempt) || recheck_large))
        return best_of_other_starts(previous, predicted, std::move(attempt), frame);
      return attempt;
    }
    frame.from_features = true;
    return std::move(*seeded);
  }
  if (is_doubtful(attempt) || recheck_large) {
    return best_of_other_starts(previous, predicted, std::move(attempt), frame);
  }
  if (images_left_open(attempt)) {
    if (std::optional<Attempt> arbitrated = arbitrate_by_intensity(attempt)) {
      frame.from_features = true;
      return std::move(*arbitrated);
    }
    return straight_if_better(previous, predicted, std::move(attempt), frame);
  }
  return attempt;
}

RgbdOdometry::Attempt RgbdOdometry::straight_if_better(std::size_t previous,
                                                       const Eigen::Isometry3d& predicted,
                                                       Attempt attempt, OdometryFrame& frame) {
  // A large step (where the features are tried) that turns more than the arbitration tells apart.
  if (!params_.straight_start_on_silent_images || !is_large(predicted) ||
      se3::rotation_angle(predicted) <= params_.feature_arbitration_deg * kDegree) {
    return attempt;
  }
  // A robot that stopped turning drives along its heading, not on the turn's arc.
  Eigen::Isometry3d straight = without_its_turn(predicted);
  if (scans_along_heading()) {
    straight.translation() = predicted.translation().norm() * heading_prior_.travel_on(straight);
  }
  Attempt other = register_frames(previous, straight, frame_limits_now());
  if (scans_along_heading() && images_left_open(other)) {
    if (std::optional<Attempt> scanned = scan_along_heading(frame.step_frame, predicted, other))
      other = std::move(*scanned);
  }
  if (!better_start(previous, other, attempt)) return attempt;
  frame.retried = true;
  return other;
}

bool RgbdOdometry::images_left_open(const Attempt& attempt) const {
  // The images did not measure the weak directions themselves (a step beyond the refinement's
  // basin, or too little texture) or left them far apart: elsewhere they already had their say.
  return geometry_.degeneracy.degenerate && attempt.photometric_rmse > 0 &&
         (!attempt.photometric || attempt.photometric_rmse > params_.photometric_doubt_rmse);
}

RgbdOdometry::Attempt RgbdOdometry::accelerating_if_better(StepFrame step_frame,
                                                           const Eigen::Isometry3d& predicted,
                                                           Attempt attempt) {
  if (!params_.acceleration_start || !geometry_.degeneracy.degenerate ||
      params_.motion_model != MotionModel::velocity) {
    return attempt;
  }
  const Eigen::Isometry3d accelerated = predict(step_frame, MotionModel::acceleration);
  if ((accelerated.translation() - predicted.translation()).norm() <=
      params_.feature_arbitration_m) {
    return attempt;  // no change of speed the images could tell
  }
  Attempt other = register_frames(frames_.size() - 1, accelerated, frame_limits_now());
  if (!agrees_better(other, attempt)) return attempt;
  other.accelerated = true;
  return other;
}

RgbdOdometry::ModelStepLengths RgbdOdometry::model_step_lengths(
    StepFrame step_frame, const Eigen::Isometry3d& predicted) const {
  return {predicted.translation().norm(),
          predict(step_frame, MotionModel::acceleration).translation().norm()};
}

std::pair<double, double> RgbdOdometry::plausible_step_lengths(
    StepFrame step_frame, const Eigen::Isometry3d& predicted) const {
  // Around the velocity and acceleration models' steps by their difference: the speed keeps
  // changing as it did, or stops changing, or changes as much again the other way.
  const auto [velocity, accelerated] = model_step_lengths(step_frame, predicted);
  const double change = std::abs(accelerated - velocity);
  double shortest = std::max(0.0, std::min(velocity, accelerated) - change);
  double longest = std::max(velocity, accelerated) + change;
  if (speed_bound_.ready()) {  // and never beyond what the drive can do
    const auto [low, high] = speed_bound_.admitted(frames_.size());
    shortest = std::max(shortest, low);
    longest = std::min(longest, high);
  }
  return {shortest, longest};
}

namespace {

// The index of the lowest of `values` above 0 (0: not measured), the first among equals; none
// where no value was measured.
std::optional<std::size_t> lowest_measured(std::span<const double> values) {
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (values[i] > 0 && (!best || values[i] < values[*best])) best = i;
  }
  return best;
}

}  // namespace

std::optional<RgbdOdometry::Attempt> RgbdOdometry::scan_step_lengths(
    StepFrame step_frame, const Eigen::Isometry3d& predicted, const Attempt& attempt) {
  constexpr double kSpacing = 0.01;  // metres: about the images' basin along a step
  const auto [shortest, longest] = plausible_step_lengths(step_frame, predicted);
  const Eigen::Vector3d step = attempt.motion.translation();
  if (!params_.step_scan || longest - shortest <= params_.feature_arbitration_m ||
      step.norm() < kSpacing) {
    return {};
  }
  std::vector<Eigen::Isometry3d> candidates;
  for (double length = shortest; length <= longest; length += kSpacing) {
    Eigen::Isometry3d candidate = attempt.motion;
    candidate.translation() = length * step.normalized();
    candidates.push_back(candidate);
  }
  const std::optional<std::size_t> best =
      lowest_measured(images_rmse(frames_.size() - 1, candidates));
  if (!best) return {};
  Attempt scanned = register_frames(frames_.size() - 1, candidates[*best], frame_limits_now());
  if (!agrees_better(scanned, attempt)) return {};
  scanned.scanned = true;
  return scanned;
}

bool RgbdOdometry::scans_along_heading() const {
  return params_.step_scan && params_.heading_scan && params_.heading_prior &&
         heading_prior_.ready() && color_ && !color_->empty();
}

std::pair<double, double> RgbdOdometry::drive_step_lengths(
    StepFrame step_frame, const Eigen::Isometry3d& predicted) const {
  // Once the drive's bound is known the images choose within all of it: the models' range
  // misses a change of speed the step before already missed.
  if (speed_bound_.ready()) return speed_bound_.admitted(frames_.size());
  return plausible_step_lengths(step_frame, predicted);
}

std::optional<RgbdOdometry::Attempt> RgbdOdometry::scan_along_heading(
    StepFrame step_frame, const Eigen::Isometry3d& predicted, const Attempt& attempt) {
  constexpr double kLengthSpacing = 0.02;  // metres: within the images' basin along a step
  constexpr double kMaxTurn = 1.5 * kDegree, kTurnSpacing = 0.15 * kDegree;
  const auto [shortest, longest] = drive_step_lengths(step_frame, predicted);
  if (longest - shortest <= params_.feature_arbitration_m) return {};
  HeadingStepGrid grid{shortest, longest, kLengthSpacing, kMaxTurn, kTurnSpacing};
  const Eigen::Vector3d axis = heading_prior_.turn_axis();
  if (axis.squaredNorm() > 0) grid.turn_axis = axis;
  grid.backwards = heading_prior_.travel_on(attempt.motion).dot(predicted.translation()) < 0;
  if (std::optional<Attempt> scanned = scan_around(attempt.motion, grid, attempt)) return scanned;
  const std::optional<Eigen::Isometry3d> turned = widest_turn_fit(predicted, grid, attempt);
  if (!turned) return {};
  return scan_around(*turned, grid, attempt);
}

std::optional<RgbdOdometry::Attempt> RgbdOdometry::scan_around(const Eigen::Isometry3d& centre,
                                                               const HeadingStepGrid& grid,
                                                               const Attempt& attempt) {
  // The attempt's own step last: the candidates must beat it clearly.
  std::vector<Eigen::Isometry3d> candidates = heading_prior_.steps_around(centre, grid);
  candidates.push_back(attempt.motion);
  const std::size_t target = frames_.size() - 1;
  const int pixel_step = params_.photometric.pixel_step;
  const std::vector<double> cost = images_disagreement(target, candidates, pixel_step);
  if (cost.empty() || cost.back() <= 0) return {};
  const auto best = std::min_element(cost.begin(), cost.end() - 1);
  Attempt scanned = register_frames(
      target, candidates[static_cast<std::size_t>(best - cost.begin())], frame_limits_now());
  if (!scanned.report.accepted()) return {};
  const std::vector<double> found = images_disagreement(target, {&scanned.motion, 1}, pixel_step);
  if (found.empty() || found[0] <= 0 ||
      found[0] >= params_.feature_arbitration_ratio * cost.back()) {
    return {};
  }
  scanned.scanned = true;
  return scanned;
}

namespace {

// `motion` with its translation shifted along `direction` (the source camera's frame) by every
// multiple of `spacing` up to `reach`, the unshifted one left out.
std::vector<Eigen::Isometry3d> shifted_along(const Eigen::Isometry3d& motion,
                                             const Eigen::Vector3d& direction, double reach,
                                             double spacing) {
  const int n = static_cast<int>(std::floor(reach / spacing + 1e-9));
  std::vector<Eigen::Isometry3d> shifted;
  for (int i = -n; i <= n; ++i) {
    if (i == 0) continue;
    Eigen::Isometry3d candidate = motion;
    candidate.translation() += motion.linear() * (i * spacing * direction);
    shifted.push_back(candidate);
  }
  return shifted;
}

// The indices of the `count` lowest costs (> 0) whose motions' translations lie more than
// `apart` metres from each other's, lowest first.
std::vector<std::size_t> lowest_apart(std::span<const double> cost,
                                      std::span<const Eigen::Isometry3d> motions, std::size_t count,
                                      double apart) {
  std::vector<std::size_t> order(cost.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return cost[a] < cost[b]; });
  std::vector<std::size_t> picked;
  for (const std::size_t k : order) {
    if (picked.size() >= count) break;
    if (cost[k] <= 0) continue;
    const bool far = std::all_of(picked.begin(), picked.end(), [&](std::size_t p) {
      return (motions[p].translation() - motions[k].translation()).norm() > apart;
    });
    if (far) picked.push_back(k);
  }
  return picked;
}

double median_of(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::vector<Eigen::Vector3d> RgbdOdometry::free_translations_now() const {
  constexpr double kFreeRatio = 0.1;  // of the largest translation information
  std::vector<Eigen::Vector3d> free = free_translations(geometry_, kFreeRatio);
  const Eigen::Vector3d axis = heading_prior_.turn_axis();
  if (!heading_prior_.ready() || axis.squaredNorm() == 0) return free;
  // A robot drives on its floor: no shift along its turning axis.
  const Eigen::Vector3d up = axis.normalized();
  std::vector<Eigen::Vector3d> level;
  for (const Eigen::Vector3d& direction : free) {
    if (std::abs(direction.dot(up)) > 0.5) continue;
    level.push_back((direction - direction.dot(up) * up).normalized());
  }
  return level;
}

Eigen::Isometry3d RgbdOdometry::basin_bottom(const Eigen::Isometry3d& start,
                                             const Eigen::Vector3d& direction, double reach) const {
  constexpr double kFine = 0.002;  // metres
  // The start first: a shift must be strictly lower to replace it.
  std::vector<Eigen::Isometry3d> shifts{start};
  for (const Eigen::Isometry3d& shifted : shifted_along(start, direction, reach, kFine)) {
    shifts.push_back(shifted);
  }
  const std::optional<std::size_t> best = lowest_measured(
      images_disagreement(frames_.size() - 1, shifts, params_.photometric.pixel_step, false));
  return shifts[best.value_or(0)];
}

std::optional<RgbdOdometry::Attempt> RgbdOdometry::scan_free_translations(const Attempt& attempt) {
  constexpr double kReach = 0.5;     // metres: a sparse sequence's change of speed, a period or two
  constexpr double kSpacing = 0.01;  // metres
  constexpr std::size_t kStarts = 4;
  constexpr double kApart = 0.045;         // metres: beyond one basin
  constexpr double kBelowTheLevel = 0.75;  // of the shifts' median: a basin, not a slope
  if (!params_.free_translation_scan || !geometry_.degeneracy.degenerate ||
      !attempt.report.accepted() ||
      attempt.photometric_rmse <= params_.free_translation_scan_rmse) {
    return {};
  }
  const std::vector<Eigen::Vector3d> free = free_translations_now();
  if (free.size() != 1) return {};
  const std::vector<Eigen::Isometry3d> shifts =
      shifted_along(attempt.motion, free[0], kReach, kSpacing);
  const std::size_t target = frames_.size() - 1;
  const int pixel_step = params_.photometric.pixel_step;
  const std::vector<double> cost = images_disagreement(target, shifts, pixel_step, false);
  // ICP from the best shifts and from the answer itself, each at the bottom of its basin.
  std::vector<Eigen::Isometry3d> starts;
  for (const std::size_t k : lowest_apart(cost, shifts, kStarts, kApart)) {
    starts.push_back(basin_bottom(shifts[k], free[0], kSpacing));
  }
  starts.push_back(basin_bottom(attempt.motion, free[0], kApart / 2));
  std::vector<Attempt> found;
  std::vector<Eigen::Isometry3d> compared{attempt.motion};
  for (const Eigen::Isometry3d& start : starts) {
    Attempt scanned = register_frames(target, start, frame_limits_now());
    if (!scanned.report.accepted()) continue;
    compared.push_back(scanned.motion);
    found.push_back(std::move(scanned));
  }
  if (found.empty()) return {};
  const std::vector<double> final_cost = images_disagreement(target, compared, pixel_step, false);
  if (final_cost.empty() || final_cost[0] <= 0) return {};
  const auto best = std::min_element(final_cost.begin() + 1, final_cost.end());
  if (*best >= params_.feature_arbitration_ratio * final_cost[0] ||
      *best >= kBelowTheLevel * median_of(cost)) {
    return {};
  }
  Attempt chosen = std::move(found[static_cast<std::size_t>(best - final_cost.begin()) - 1]);
  chosen.scanned = true;
  return chosen;
}

std::optional<Eigen::Isometry3d> RgbdOdometry::widest_turn_fit(const Eigen::Isometry3d& predicted,
                                                               const HeadingStepGrid& grid,
                                                               const Attempt& attempt) const {
  if (!params_.wide_turn_scan || attempt.photometric_rmse <= params_.photometric_doubt_rmse ||
      predicted.translation().norm() <= params_.feature_seed_m) {
    return {};
  }
  HeadingStepGrid wide = grid;
  wide.max_turn = 40 * kDegree;
  wide.turn_spacing = 1 * kDegree;
  const std::vector<Eigen::Isometry3d> candidates =
      heading_prior_.steps_around(attempt.motion, wide);
  const std::vector<double> cost =
      images_disagreement(frames_.size() - 1, candidates, 2 * params_.photometric.pixel_step);
  const auto best = std::min_element(cost.begin(), cost.end());
  if (best == cost.end() || *best <= 0) return {};  // no colour, or too few textured pixels
  // Within the scan around the attempt's own turn, which found nothing.
  const Eigen::Isometry3d found = candidates[static_cast<std::size_t>(best - cost.begin())];
  if (se3::rotation_angle(attempt.motion.inverse() * found) <= grid.max_turn) return {};
  return found;
}

std::optional<RgbdOdometry::Attempt> RgbdOdometry::arbitrate_by_intensity(
    const Attempt& predicted) {
  std::optional<Attempt> seeded = register_from_features();
  if (!seeded || !agrees_better(*seeded, predicted)) return {};
  return seeded;
}

bool RgbdOdometry::within_arbitration(const Attempt& a, const Attempt& b) const {
  const Eigen::Isometry3d difference = a.motion.inverse() * b.motion;
  return difference.translation().norm() <= params_.feature_arbitration_m &&
         se3::rotation_angle(difference) <= params_.feature_arbitration_deg * kDegree;
}

bool RgbdOdometry::images_tell_apart(const Attempt& challenger, const Attempt& incumbent) const {
  // Two answers of a degenerate view within the arbitration distance differ along the free
  // directions, which only the images measure (a turn on the spot: the features' 3 cm slide).
  return params_.feature_ties_by_images && challenger.report.accepted() &&
         within_arbitration(challenger, incumbent) &&
         (challenger.report.degenerate || incumbent.report.degenerate) && challenger.photometric &&
         challenger.photometric_rmse > 0 && incumbent.photometric_rmse > 0 &&
         challenger.photometric_rmse <
             params_.feature_arbitration_ratio * incumbent.photometric_rmse;
}

bool RgbdOdometry::neither_images_fit(const Attempt& predicted, const Attempt& seeded) const {
  const auto misfit = [&](const Attempt& a) {
    return a.report.accepted() && !a.photometric &&
           a.photometric_rmse > params_.photometric_doubt_rmse;
  };
  return (predicted.report.degenerate || seeded.report.degenerate) && misfit(predicted) &&
         misfit(seeded) && !within_arbitration(predicted, seeded) &&
         speed_allows(predicted) == speed_allows(seeded);
}

bool RgbdOdometry::keeps_prediction(const Attempt& predicted, const Attempt& seeded) {
  if (params_.features_over_misfit_images && neither_images_fit(predicted, seeded)) return false;
  if (agrees_better(predicted, seeded) || images_tell_apart(predicted, seeded)) return true;
  return params_.prediction_keeps_image_ties && predicted.report.accepted() &&
         predicted.photometric && seeded.photometric && !within_arbitration(predicted, seeded) &&
         !agrees_better(seeded, predicted);
}

bool RgbdOdometry::agrees_better(const Attempt& challenger, const Attempt& incumbent) {
  if (!challenger.report.accepted() || within_arbitration(challenger, incumbent)) return false;
  if (challenger.report.degenerate || incumbent.report.degenerate) {
    // The images can prefer a repeated floor pattern a tile over: a step the robot cannot make
    // loses first.
    if (const std::optional<bool> allowed = speed_decides(challenger, incumbent)) return *allowed;
    return challenger.photometric_rmse > 0 && incumbent.photometric_rmse > 0 &&
           challenger.photometric_rmse <
               params_.feature_arbitration_ratio * incumbent.photometric_rmse;
  }
  return fits_better(frames_.size() - 1, challenger, incumbent);
}

std::optional<bool> RgbdOdometry::speed_decides(const Attempt& challenger,
                                                const Attempt& incumbent) {
  const bool allowed = speed_allows(challenger);
  if (allowed == speed_allows(incumbent)) return std::nullopt;
  speed_bound_decided_ = true;
  return allowed;
}

bool RgbdOdometry::speed_allows(const Attempt& attempt) const {
  return speed_bound_.admits(frames_.size(), attempt.motion.translation().norm());
}

bool RgbdOdometry::is_doubtful(const Attempt& attempt) const {
  // Rejected, moved far from the prediction (the motion changed: a turn that stopped, a start, a
  // stop, and a weakly constrained view may have let ICP settle in a neighbouring basin), or
  // little overlap (the motion may be beyond the basin).
  return !attempt.report.accepted() || attempt.report.correction_m > params_.recheck_correction_m ||
         attempt.report.fitness < params_.recheck_fitness;
}

std::vector<Eigen::Isometry3d> RgbdOdometry::other_starts(
    const Eigen::Isometry3d& predicted) const {
  Eigen::Isometry3d turn_only = predicted;
  turn_only.translation().setZero();
  std::vector<Eigen::Isometry3d> starts = {Eigen::Isometry3d::Identity(), turn_only,
                                           without_its_turn(predicted)};
  // Turns about the camera's vertical axis beyond the prediction: a robot's or a person's turn is
  // the motion most often beyond ICP's basin.
  for (const double degrees : params_.recheck_turns_deg) {
    Eigen::Isometry3d turned = predicted;
    turned.linear() =
        predicted.linear() *
        Eigen::AngleAxisd(degrees * kDegree, Eigen::Vector3d::UnitY()).toRotationMatrix();
    starts.push_back(turned);
  }
  return starts;
}

RgbdOdometry::Attempt RgbdOdometry::best_of_other_starts(std::size_t previous,
                                                         const Eigen::Isometry3d& predicted,
                                                         Attempt first, OdometryFrame& frame) {
  // The pair is the same for every start: the speed bound and the images where they are
  // decisive, else the fitness, choose (better_start); the first stays on a tie.
  Attempt best = held_on_its_overlap(previous, predicted, std::move(first));
  const auto consider = [&](Attempt other, bool seeded_by_features) {
    if (!better_start(previous, other, best)) return;
    best = std::move(other);
    frame.retried = !seeded_by_features;
    frame.from_features = seeded_by_features;
  };
  const auto from = [&](const Eigen::Isometry3d& start) {
    return held_on_its_overlap(previous, start,
                               register_frames(previous, start, frame_limits_now()));
  };
  for (const Eigen::Isometry3d& start : other_starts(predicted)) {
    if (is_identity(predicted.inverse() * start)) continue;  // where the first one started
    consider(from(start), false);
  }
  if (std::optional<Attempt> seeded = register_from_features()) consider(std::move(*seeded), true);
  if (params_.recheck_from_turn && best.report.accepted()) {
    for (const Eigen::Isometry3d& start : starts_from_turn(best.motion)) {
      consider(from(start), false);
    }
  }
  return best;
}

std::vector<double> RgbdOdometry::images_rmse(std::size_t target,
                                              std::span<const Eigen::Isometry3d> motions) const {
  const PhotometricFrame& source = images_[slot_of(frames_.size())];
  const PhotometricFrame& onto = images_[slot_of(target)];
  if (source.empty() || onto.empty()) return {};
  return intensity_rmse(source, onto, builder_.camera(), motions, params_.photometric);
}

std::vector<double> RgbdOdometry::images_disagreement(std::size_t target,
                                                      std::span<const Eigen::Isometry3d> motions,
                                                      int pixel_step, bool unseen_at_cap) const {
  const PhotometricFrame& source = images_[slot_of(frames_.size())];
  const PhotometricFrame& onto = images_[slot_of(target)];
  if (source.empty() || onto.empty()) return {};
  PhotometricParams photometric = params_.photometric;
  photometric.pixel_step = pixel_step;
  photometric.unseen_at_cap = unseen_at_cap;
  return intensity_disagreement(source, onto, builder_.camera(), motions, photometric);
}

double RgbdOdometry::images_rmse_at(std::size_t target, Attempt& attempt) const {
  if (attempt.start_rmse < 0) {
    const std::vector<double> rmse = images_rmse(target, {&attempt.motion, 1});
    attempt.start_rmse = rmse.empty() ? 0 : rmse[0];
    if (params_.recheck_images_refined && attempt.start_rmse > 0 && attempt.refined_rmse > 0) {
      attempt.start_rmse = std::min(attempt.start_rmse, attempt.refined_rmse);
    }
  }
  return attempt.start_rmse;
}

std::optional<bool> RgbdOdometry::images_decide(std::size_t target, Attempt& challenger,
                                                Attempt& incumbent) const {
  const double rmse_challenger = images_rmse_at(target, challenger);
  const double rmse_incumbent = images_rmse_at(target, incumbent);
  const auto decisive = [&](double winner, double loser) {
    return winner > 0 && winner <= params_.photometric_doubt_rmse &&
           winner < params_.recheck_images_ratio * loser;
  };
  if (decisive(rmse_challenger, rmse_incumbent)) return true;
  if (decisive(rmse_incumbent, rmse_challenger)) return false;
  return std::nullopt;
}

bool RgbdOdometry::better_start(std::size_t target, Attempt& other, Attempt& best) {
  if (!other.report.accepted()) return false;
  if (!best.report.accepted()) return true;
  if (params_.recheck_by_images && !within_arbitration(other, best)) {
    if (other.report.degenerate || best.report.degenerate) {
      if (const std::optional<bool> allowed = speed_decides(other, best)) return *allowed;
    }
    if (const std::optional<bool> decided = images_decide(target, other, best)) return *decided;
  }
  return fits_better(target, other, best);
}

bool RgbdOdometry::fits_better(std::size_t target, const Attempt& challenger,
                               const Attempt& incumbent) {
  if (params_.fitness_weighed_by_view && !within_arbitration(challenger, incumbent)) {
    return view_weighed_fitness(target, challenger) > view_weighed_fitness(target, incumbent);
  }
  return challenger.report.fitness > incumbent.report.fitness;
}

std::vector<Eigen::Isometry3d> RgbdOdometry::starts_from_turn(
    const Eigen::Isometry3d& motion) const {
  // A turn moves most points far more than the slide it can be traded for, so ICP's turn is
  // better than its step: that turn again, on the spot and with the same step length along the
  // heading (the prior's, or the predicted step's before it is ready) on the turn's arc.
  Eigen::Isometry3d on_the_spot = motion;
  on_the_spot.translation().setZero();
  std::vector<Eigen::Isometry3d> starts = {on_the_spot};
  if (!heading_prior_.ready() && !params_.arc_start_from_the_prediction) return starts;
  if (const Eigen::Vector3d travel = travel_on_arc(motion); travel.squaredNorm() > 0) {
    Eigen::Isometry3d on_the_arc = motion;
    on_the_arc.translation() = motion.translation().norm() * travel;
    starts.push_back(on_the_arc);
  }
  return starts;
}

void RgbdOdometry::track_previous(OdometryFrame& frame) {
  const std::size_t n = frame.index;
  frame.step_frame = step_frame_in_use();
  const Eigen::Isometry3d predicted = predict(frame.step_frame);
  large_step_ = is_large(predicted);
  speed_bound_decided_ = false;
  const GeometricInformation whole_frame = geometry_;
  const Attempt attempt =
      judged_on_the_overlap(predicted, frame, attempt_previous(predicted, frame));
  frame.previous = attempt.report;
  frame.accelerated = attempt.accelerated;
  frame.scanned = attempt.scanned;
  frame.speed_bounded = speed_bound_decided_;
  frame.photometric = attempt.photometric;
  frame.deep_photometric = attempt.deep_photometric;
  frame.heading_sigma_m = attempt.heading_sigma_m;
  // What the motion model, the heading prior and the bounds learn from stays with the whole
  // frame's geometry: a wide turn's step held on the overlap still measured its turn, and they
  // were tuned with those steps among the measured ones.
  const bool degenerate = whole_frame.degeneracy.degenerate;
  if (attempt.report.accepted() && !degenerate) {
    score_step_frames(attempt.motion);
    largest_step_m_ = std::max(largest_step_m_, attempt.motion.translation().norm());
  }
  const bool measured =
      !degenerate || (params_.speed_bound_learns_from_images && attempt.photometric);
  if (attempt.report.accepted() && measured) {
    speed_bound_.learn(n, attempt.motion.translation().norm());
  }

  RelativePose constraint{n - 1, n, predicted, {}, false};
  if (attempt.report.accepted()) {
    constraint.motion = attempt.motion;
    constraint.information = information_of(attempt);
  } else {
    // Keep moving as before rather than chain a registration that failed its checks.
    frame.fallback = true;
    constraint.fallback = true;
    constraint.information =
        prior_information(params_.fallback_sigma_deg * kDegree, params_.fallback_sigma_m);
  }
  constraints_.push_back(constraint);
  poses_.push_back(orthonormalized(poses_.back() * constraint.motion));
  geometry_ = whole_frame;
}

bool RgbdOdometry::turns_wide_on_a_constrained_view(const Attempt& attempt) const {
  return params_.overlap_turn_deg > 0 && attempt.report.accepted() &&
         !geometry_.degeneracy.degenerate &&
         se3::rotation_angle(attempt.motion) > params_.overlap_turn_deg * kDegree;
}

bool RgbdOdometry::overlap_answer_stands(std::size_t previous, Attempt& first,
                                         Attempt& held) const {
  // Unless the images side with the first answer: at seed 4's frame 920 (a turn on the spot)
  // the images measured the degenerate view's free directions 3.5 cm and 1.1 degrees off, where
  // the first answer, from the turn on the spot, fitted them at an RMSE of 1.2.
  return held.report.accepted() && !images_decide(previous, first, held).value_or(false);
}

RgbdOdometry::Attempt RgbdOdometry::judged_on_the_overlap(const Eigen::Isometry3d& predicted,
                                                          OdometryFrame& frame, Attempt attempt) {
  if (!turns_wide_on_a_constrained_view(attempt)) return attempt;
  GeometricInformation overlap = overlap_geometry(frame.index, frame.index - 1, attempt.motion);
  if (!overlap.degeneracy.degenerate) return attempt;
  // Registered again as a degenerate view: its free directions from the prior and the images.
  const OdometryFrame as_constrained = frame;
  const bool speed_decided = speed_bound_decided_;
  GeometricInformation whole_frame = std::exchange(geometry_, std::move(overlap));
  frame.degenerate = frame.degenerate_overlap = true;
  frame.eigenvalue_ratio = geometry_.degeneracy.eigenvalue_ratio;
  frame.retried = frame.from_features = false;
  speed_bound_decided_ = false;
  Attempt degenerate = attempt_previous(predicted, frame);
  if (!overlap_answer_stands(frame.index - 1, attempt, degenerate)) {
    geometry_ = std::move(whole_frame);
    frame = as_constrained;
    speed_bound_decided_ = speed_decided;
    return attempt;
  }
  return degenerate;
}

RgbdOdometry::Attempt RgbdOdometry::held_on_its_overlap(std::size_t previous,
                                                        const Eigen::Isometry3d& start,
                                                        Attempt attempt) {
  if (!params_.overlap_every_start || !turns_wide_on_a_constrained_view(attempt)) return attempt;
  std::optional<HeldOnOverlap> held =
      held_where_degenerate(previous, attempt.motion, start, frame_limits_now());
  if (!held) return attempt;
  return overlap_answer_stands(previous, attempt, held->attempt) ? held->attempt : attempt;
}

std::optional<RgbdOdometry::HeldOnOverlap> RgbdOdometry::held_where_degenerate(
    std::size_t target, const Eigen::Isometry3d& motion, const Eigen::Isometry3d& start,
    const RegistrationLimits& limits) {
  GeometricInformation overlap = overlap_geometry(frames_.size(), target, motion);
  if (!overlap.degeneracy.degenerate) return std::nullopt;
  // From `start` as a degenerate view: the prior holds what the shared part leaves free.
  GeometricInformation whole_frame = std::exchange(geometry_, std::move(overlap));
  HeldOnOverlap held;
  held.attempt = register_frames(target, start, limits);
  held.information = information_of(held.attempt);
  geometry_ = std::move(whole_frame);
  return held;
}

double RgbdOdometry::view_weighed_fitness(std::size_t target, const Attempt& attempt) {
  // Shares of the points mapped onto the other frame's surfaces: those within the overlap's
  // gap of them, against those where that camera saw past them to a surface behind.
  const auto [source, onto] = information_levels(frames_.size(), target);
  const std::vector<ViewRelation> relations =
      view_relations(source.view(), onto.view(), onto.camera, attempt.motion, overlap_gap_m());
  const auto count = [&](ViewRelation r) {
    return static_cast<double>(std::count(relations.begin(), relations.end(), r));
  };
  const double agreeing = count(ViewRelation::agrees);
  const double contradicting = count(ViewRelation::seen_through);
  const double judged = agreeing + contradicting;
  if (judged == 0) return 0;
  const double excess = std::max(0.0, contradicting - params_.contradiction_floor * judged);
  return attempt.report.fitness * (agreeing - params_.contradiction_weight * excess) / judged;
}

GeometricInformation RgbdOdometry::overlap_geometry(std::size_t current, std::size_t target,
                                                    const Eigen::Isometry3d& motion) {
  const auto [source, onto] = information_levels(current, target);
  const std::vector<std::uint8_t> keep =
      overlapping_points(source.view(), onto.view(), onto.camera, motion, overlap_gap_m());
  return level_geometry(source.view(), keep);
}

std::pair<const PyramidLevel&, const PyramidLevel&> RgbdOdometry::information_levels(
    std::size_t current, std::size_t target) {
  return {pyramid_of(current).level(information_level_),
          pyramid_of(target).level(information_level_)};
}

double RgbdOdometry::overlap_gap_m() const {
  // The coarsest ICP level's pair distance: what a registration of the two frames can still match.
  return params_.icp.levels.back().max_distance;
}

GeometricInformation RgbdOdometry::level_geometry(const CloudView& level,
                                                  std::span<const std::uint8_t> keep) const {
  return geometric_information(
      level, params_.depth_weighting ? params_.depth_weights.reference_depth : 0.0,
      params_.icp.min_eigenvalue_ratio, keep);
}

RgbdOdometry::ReestimateLimits RgbdOdometry::reestimate_limits(const OdometryFrame& frame,
                                                               std::size_t anchor) const {
  const auto since = [&](std::size_t first, auto predicate) {
    return predicate(frame) || std::any_of(frames_.begin() + static_cast<std::ptrdiff_t>(first),
                                           frames_.end(), predicate);
  };
  const auto k = static_cast<std::size_t>(params_.reestimate_interval);
  ReestimateLimits limits{params_.reestimate_limits, false};
  // A fallback since the last re-estimate leaves the chained estimate less certain, and so do
  // degenerate frames since the anchor when this view is not degenerate: their free directions
  // came from the motion model, and this view measures them. Allow what a single frame-to-frame
  // registration may correct; after degenerate frames, only when the images confirm it.
  const bool after_fallback =
      since(frame.index - k + 1, [](const OdometryFrame& f) { return f.fallback; });
  limits.needs_images = !after_fallback && !geometry_.degeneracy.degenerate &&
                        since(anchor + 1, [](const OdometryFrame& f) { return f.degenerate; });
  if (after_fallback || limits.needs_images) {
    limits.limits.max_correction_m =
        std::max(limits.limits.max_correction_m, params_.frame_limits.max_correction_m);
    limits.limits.max_correction_deg =
        std::max(limits.limits.max_correction_deg, params_.frame_limits.max_correction_deg);
  }
  return limits;
}

// A correction beyond the usual limits after degenerate frames: either the chain drifted in
// their free directions or ICP against the anchor slid along its own weak ones (survey seed 7,
// frames 1230-1235: 6.7 cm with a chain right to 1 mm). The images decide, as between two
// starts (agrees_better): the grey levels must agree clearly better at the re-estimate.
bool RgbdOdometry::images_confirm(std::size_t anchor, const Eigen::Isometry3d& motion,
                                  const Eigen::Isometry3d& chained) const {
  const Eigen::Isometry3d candidates[] = {motion, chained};
  const std::vector<double> rmse = images_rmse(anchor, candidates);
  if (rmse.empty()) return false;
  const double at_reestimate = rmse[0], at_chain = rmse[1];
  return at_reestimate > 0 && at_chain > 0 &&
         at_reestimate < params_.feature_arbitration_ratio * at_chain;
}

void RgbdOdometry::reestimate(OdometryFrame& frame) {
  const std::size_t n = frame.index;
  const auto k = static_cast<std::size_t>(params_.reestimate_interval);
  if (n < k) return;
  const std::size_t anchor = anchor_;
  const Eigen::Isometry3d anchor_pose = poses_[anchor];
  const Eigen::Isometry3d chained = anchor_pose.inverse() * poses_[n];
  const ReestimateLimits limits = reestimate_limits(frame, anchor);
  auto [attempt, information, on_overlap] = register_against_anchor(anchor, chained, limits.limits);
  frame.reestimate_degenerate_overlap = on_overlap;
  const RegistrationLimits& usual = params_.reestimate_limits;
  if (limits.needs_images && attempt.report.accepted() &&
      (attempt.report.correction_m > usual.max_correction_m ||
       attempt.report.correction_deg > usual.max_correction_deg) &&
      !images_confirm(anchor, attempt.motion, chained)) {
    attempt.report.verdict = RegistrationVerdict::unconfirmed;
  }
  frame.reestimate = attempt.report;
  frame.reestimate_anchor = anchor;
  if (!attempt.report.accepted()) {
    anchor_ = n;  // the chain is all there is from here on
    return;
  }
  constraints_.push_back({anchor, n, attempt.motion, information, false});
  // Spread the correction (a motion in the anchor's frame) over the frames since the last
  // re-estimate, n-k, whose pose stays.
  const se3::Vector6d correction = se3::log(attempt.motion * chained.inverse());
  for (std::size_t j = n - k + 1; j <= n; ++j) {
    const double share = static_cast<double>(j - (n - k)) / static_cast<double>(k);
    poses_[j] = orthonormalized(anchor_pose * se3::exp(share * correction) *
                                (anchor_pose.inverse() * poses_[j]));
  }
  if (params_.steps_follow_reestimates) rechain_steps_from(n - k + 1);
  if (moves_anchor(n)) anchor_ = n;
}

void RgbdOdometry::rechain_steps_from(std::size_t first) {
  // Constraints are appended frame by frame: the steps to frames first.. are the newest.
  for (auto c = constraints_.rbegin(); c != constraints_.rend() && c->to >= first; ++c) {
    if (c->from + 1 == c->to) c->motion = poses_[c->from].inverse() * poses_[c->to];
  }
}

RgbdOdometry::AnchoredAttempt RgbdOdometry::register_against_anchor(
    std::size_t anchor, const Eigen::Isometry3d& chained, const RegistrationLimits& limits) {
  Attempt attempt = register_frames(anchor, chained, limits);
  // Where what the two views share leaves directions free, registered again as a degenerate
  // view the chain (the motion prior) and the images hold them. That answer replaces the first
  // where the images side with it (grey-level RMSE at most photometric_doubt_rmse and under
  // recheck_images_ratio times the first's: seed 16 4.8 against 27.3), not otherwise: on survey
  // seed 4, frame 155, the chain had drifted 2.1 degrees in degenerate frames and the first
  // answer measured it (RMSE 31.6 against 24.3, neither decisive).
  std::optional<HeldOnOverlap> held;
  if (params_.reestimate_on_overlap && !geometry_.degeneracy.degenerate &&
      attempt.report.accepted())
    held = held_where_degenerate(anchor, attempt.motion, chained, limits);
  if (held && held->attempt.report.accepted() &&
      images_decide(anchor, held->attempt, attempt).value_or(false))
    return {held->attempt, held->information, true};
  return {attempt, information_of(attempt)};
}

bool RgbdOdometry::moves_anchor(std::size_t n) const {
  // Judged where the next re-estimate will be, k frames on at the last k frames' motion, so that
  // no re-estimate spans more than the bounds (on the synthetic surveys a robot turning on the
  // spot turns 20 degrees between two re-estimates; judged at n, re-estimates spanning 39 degrees
  // were 1-3.5 cm off).
  const AnchorPolicy& policy = params_.anchor;
  const auto k = static_cast<std::size_t>(params_.reestimate_interval);
  const Eigen::Isometry3d window = poses_[n - k].inverse() * poses_[n];
  const Eigen::Isometry3d next = poses_[anchor_].inverse() * poses_[n] * window;
  return n + k - anchor_ > static_cast<std::size_t>(policy.max_interval) ||
         next.translation().norm() > policy.max_translation ||
         se3::rotation_angle(next) > policy.max_rotation_deg * kDegree;
}

std::optional<RgbdOdometry::Attempt> RgbdOdometry::register_from_features() {
  if (!params_.features || !color_ || color_->empty() || previous_color_.empty()) return {};
  const FeatureFrontEnd& features = *params_.features;
  const double units = params_.depth_range.units_per_metre;
  if (!current_features_) {
    current_features_ = features.describe(*depth_, *color_, builder_.camera(), units);
  }
  if (!previous_features_) {
    previous_features_ =
        features.describe(previous_depth_, previous_color_, builder_.camera(), units);
  }
  const std::optional<FeatureAlignment> aligned =
      features.align(*current_features_, *previous_features_);
  if (!aligned) return {};
  Attempt attempt =
      register_frames(frames_.size() - 1, aligned->source_to_target, frame_limits_now());
  if (!attempt.report.accepted()) return {};
  return attempt;
}

RgbdOdometry::Attempt RgbdOdometry::features_turn_on_the_arc(StepFrame step_frame,
                                                             const Eigen::Isometry3d& predicted,
                                                             Attempt seeded) {
  if (!params_.features_turn_on_the_arc || !geometry_.degeneracy.degenerate) return seeded;
  const Eigen::Vector3d travel = travel_on_arc(seeded.motion);
  if (travel.squaredNorm() == 0) return seeded;
  Eigen::Isometry3d start = seeded.motion;
  start.translation() = predicted.translation().norm() * travel;
  Attempt on_the_arc = register_frames(frames_.size() - 1, start, frame_limits_now());
  if (params_.features_along_the_drive && !heading_prior_.ready() && on_the_arc.report.accepted() &&
      across_the_drive(seeded.motion, travel)) {
    return speeding_up_on_the_arc(step_frame, predicted, start, travel, std::move(on_the_arc));
  }
  Attempt chosen = agrees_better(on_the_arc, seeded) ? std::move(on_the_arc) : std::move(seeded);
  return speeding_up_on_the_arc(step_frame, predicted, start, travel, std::move(chosen));
}

RgbdOdometry::Attempt RgbdOdometry::speeding_up_on_the_arc(StepFrame step_frame,
                                                           const Eigen::Isometry3d& predicted,
                                                           Eigen::Isometry3d start,
                                                           const Eigen::Vector3d& travel,
                                                           Attempt chosen) {
  // As acceleration_start does for the prediction: the robot may be speeding up on that turn,
  // or slowing down as much.
  if (!params_.acceleration_start || !params_.acceleration_on_the_arc) return chosen;
  const auto [velocity, accelerated] = model_step_lengths(step_frame, predicted);
  const double change = accelerated - velocity;
  if (std::abs(change) <= params_.feature_arbitration_m) return chosen;
  for (const double length : {velocity + change, velocity - change}) {
    if (length <= 0) continue;
    start.translation() = length * travel;
    Attempt changed = register_frames(frames_.size() - 1, start, frame_limits_now());
    // Only a step the images measured, and fit clearly better: unrefined, or refined but barely
    // better, they can prefer a shorter step on a floor.
    const bool images_fit =
        changed.photometric &&
        changed.photometric_rmse < params_.acceleration_on_the_arc_ratio * chosen.photometric_rmse;
    if (!images_fit || !agrees_better(changed, chosen)) continue;
    changed.accelerated = true;
    chosen = std::move(changed);
  }
  return chosen;
}

bool RgbdOdometry::across_the_drive(const Eigen::Isometry3d& step,
                                    const Eigen::Vector3d& travel) const {
  const Eigen::Vector3d t = step.translation();
  const double along = t.dot(travel);
  return t.norm() > params_.feature_arbitration_m && (t - along * travel).norm() > along;
}

Eigen::Vector3d RgbdOdometry::travel_on_arc(const Eigen::Isometry3d& step) const {
  if (heading_prior_.ready()) return heading_prior_.travel_on(step);
  const Eigen::Vector3d heading = untwisted(predict(StepFrame::camera));
  if (heading.norm() < 1e-3) return Eigen::Vector3d::Zero();  // a turn on the spot: no heading
  return registration::travel_on_arc(heading, step);
}

void RgbdOdometry::keep_images_for_features(const DepthImage& depth, const RgbImage* color) {
  // This frame's description, if one was made, serves as the next frame's previous one.
  previous_features_ = std::move(current_features_);
  current_features_.reset();
  if (!params_.features || !color || color->empty()) {
    previous_color_ = RgbImage();
    return;
  }
  previous_depth_ = depth;
  previous_color_ = *color;
}

bool RgbdOdometry::is_keyframe(const OdometryFrame& frame) const {
  if (keyframes_.empty() || frame.fallback) return true;
  const std::size_t last = keyframes_.back();
  const KeyframePolicy& policy = params_.keyframes;
  if (frame.index - last >= static_cast<std::size_t>(policy.max_interval)) return true;
  const Eigen::Isometry3d motion = poses_[last].inverse() * poses_[frame.index];
  return motion.translation().norm() >= policy.min_translation ||
         se3::rotation_angle(motion) >= policy.min_rotation_deg * kDegree;
}

}  // namespace kartograf::registration
