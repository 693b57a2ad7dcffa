#include "kartograf/mapping/online_slam.hpp"

#include <algorithm>
#include <chrono>
#include <numbers>
#include <optional>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/mapping/chain_covariance.hpp"

namespace kartograf::mapping {

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kDegree = std::numbers::pi / 180.0;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

registration::OdometryParams with_units(registration::OdometryParams params,
                                        double depth_units_per_metre) {
  params.depth_range.units_per_metre = depth_units_per_metre;
  return params;
}

const RgbImage* color_of(const registration::RgbdImages& images) {
  return images.color.empty() ? nullptr : &images.color;
}

// Tracks every frame of a source, keeping what both runs report.
class Tracker {
 public:
  Tracker(const compute::Context& context, const PinholeIntrinsics& camera,
          double depth_units_per_metre, const registration::OdometryParams& params,
          const ModelTrackingParams& model = {})
      : odometry_(
            context, camera,
            with_units(model.enabled ? model.predicting(params) : params, depth_units_per_metre)) {
    if (model.enabled) {
      model_.emplace(context, camera, odometry_.params().depth_range, model);
      run_.model_tracking = true;
    }
  }

  const registration::OdometryFrame& track(const registration::RgbdImages& images) {
    run_.timestamps.push_back(images.timestamp);
    const registration::OdometryFrame& frame =
        odometry_.track(images.depth, color_of(images), images.motion_prior);
    run_.compute_seconds += frame.seconds;
    if (model_) track_model(images);
    const std::size_t n = poses().size() - 1;
    path_.push_back(n == 0 ? 0.0
                           : path_.back() +
                                 (poses()[n].translation() - poses()[n - 1].translation()).norm());
    return frame;
  }

  const registration::RgbdOdometry& odometry() const { return odometry_; }
  double path_length(std::size_t frame) const { return path_[frame]; }
  // The tracking's poses and relative poses: the model's with model tracking, else the
  // odometry's.
  const std::vector<Eigen::Isometry3d>& poses() const {
    return model_ ? model_poses_ : odometry_.poses();
  }
  const std::vector<registration::RelativePose>& constraints() const {
    return model_ ? model_constraints_ : odometry_.constraints();
  }

  OdometryRun finish(const FrameLoopTiming& timing = {}) {
    run_.poses = poses();
    run_.frames = odometry_.frames();
    run_.constraints = constraints();
    run_.keyframes = odometry_.keyframes();
    run_.timing = timing;
    return std::move(run_);
  }

 private:
  // The odometry's motion since the last frame, applied to the model's pose of that frame.
  void track_model(const registration::RgbdImages& images) {
    const auto start = Clock::now();
    const auto& odometry = odometry_.poses();
    const std::size_t n = odometry.size() - 1;
    const Eigen::Isometry3d predicted =
        n == 0 ? odometry[0] : model_poses_.back() * (odometry[n - 1].inverse() * odometry[n]);
    const registration::FramePyramid& pyramid = odometry_.latest_pyramid();
    const ModelTrackingStep step =
        model_->track(images.depth, color_of(images), predicted,
                      model_->can_register(pyramid) ? &pyramid : nullptr);
    model_poses_.push_back(step.pose);
    add_model_constraints(n);
    run_.model_kept += step.from_model ? 1 : 0;
    run_.model_evictions += step.evicted_blocks > 0 ? 1 : 0;
    run_.model_seconds += seconds_since(start);
  }

  // The odometry's new constraints as the graph's: its step to frame n becomes the model's motion
  // from frame n-1 to n, with the odometry's information of that step (the same frame's geometry
  // measured it; the model's surface is smoother than frame n-1's, so this understates the
  // model's certainty, never overstates it). Any other (a re-estimate against an anchor; none
  // while ModelTrackingParams::predicting turns them off) stays as it is. With the re-estimates'
  // edges in the graph SLAM was worse on 7-Scenes, SUN3D and two of the synthetic sequences.
  void add_model_constraints(std::size_t n) {
    const std::vector<registration::RelativePose>& all = odometry_.constraints();
    for (; odometry_constraints_seen_ < all.size(); ++odometry_constraints_seen_) {
      registration::RelativePose constraint = all[odometry_constraints_seen_];
      if (constraint.to == n && constraint.from + 1 == n) {
        constraint.motion = model_poses_[n - 1].inverse() * model_poses_[n];
      }
      model_constraints_.push_back(constraint);
    }
  }

  registration::RgbdOdometry odometry_;
  std::optional<ModelTracker> model_;
  std::vector<Eigen::Isometry3d> model_poses_;
  std::vector<registration::RelativePose> model_constraints_;
  std::size_t odometry_constraints_seen_ = 0;
  OdometryRun run_;
  std::vector<double> path_;
};

PoseGraphEdge edge_of(const registration::RelativePose& pose, bool loop_closure) {
  return {pose.from, pose.to, pose.motion, pose.information, loop_closure};
}

// The SLAM estimate while frames arrive: optimised poses up to the last optimisation (the
// anchor), odometry-relative poses after it; loop closures kept for the graph.
class GraphState {
 public:
  GraphState(const PoseGraphParams& options, const LoopConsistency& consistency)
      : options_(options), consistency_(consistency) {}

  // Brings the estimate of frames after the anchor up to date with the odometry: the new frame,
  // and the last k poses when it was re-estimated (every k-th frame), so the work per frame does
  // not grow with k.
  void follow(const std::vector<Eigen::Isometry3d>& odometry, std::size_t reestimate_interval) {
    const std::size_t last = odometry.size() - 1;
    estimate_.resize(odometry.size());
    const std::size_t k = reestimate_interval;
    const bool reestimated = k > 0 && last >= k && last % k == 0;
    const std::size_t first = std::max(anchor_ + 1, reestimated ? last - k : last);
    const Eigen::Isometry3d offset = anchor_estimate_ * anchor_odometry_.inverse();
    for (std::size_t m = first; m <= last; ++m) estimate_[m] = offset * odometry[m];
    if (last == 0) estimate_[0] = odometry[0];
  }

  void add_loop(const LoopClosure& closure, std::size_t record) {
    loops_.push_back({edge_of(closure.constraint, true), record});
  }

  // Optimises frames 0..estimate().size()-1 with every constraint and the active loop closures.
  // Loop closures that the graph prunes (chi^2), or whose residual after optimisation exceeds
  // the consistency limits (the worst one first, then optimising again), are dropped and marked
  // in `records`.
  PoseGraphSummary optimise(const std::vector<registration::RelativePose>& constraints,
                            const std::vector<Eigen::Isometry3d>& odometry,
                            std::vector<LoopClosureRecord>& records) {
    std::vector<bool> dropped(loops_.size(), false);
    std::vector<Eigen::Isometry3d> poses = estimate_;
    PoseGraphSummary summary;
    int total_iterations = 0;
    while (true) {
      PoseGraph graph;
      graph.poses = poses;
      for (const auto& c : constraints) graph.edges.push_back(edge_of(c, false));
      std::vector<std::size_t> loop_of_edge(graph.edges.size(), loops_.size());
      for (std::size_t l = 0; l < loops_.size(); ++l) {
        if (dropped[l]) continue;
        graph.edges.push_back(loops_[l].edge);
        loop_of_edge.push_back(l);
      }
      summary = optimize_pose_graph(graph, options_);
      total_iterations += summary.iterations;
      for (const std::size_t edge : summary.pruned_edges) {
        if (loop_of_edge[edge] < loops_.size()) dropped[loop_of_edge[edge]] = true;
      }
      poses = std::move(graph.poses);
      edge_count_ = graph.edges.size();
      const std::size_t worst = least_consistent_loop(poses, dropped);
      if (worst == loops_.size()) break;
      dropped[worst] = true;
    }
    summary.iterations = total_iterations;
    std::vector<ActiveLoop> kept;
    for (std::size_t l = 0; l < loops_.size(); ++l) {
      if (dropped[l]) {
        records[loops_[l].record].pruned = true;
      } else {
        kept.push_back(loops_[l]);
      }
    }
    loops_ = std::move(kept);
    estimate_ = std::move(poses);
    anchor_ = estimate_.size() - 1;
    anchor_estimate_ = estimate_[anchor_];
    anchor_odometry_ = odometry[anchor_];
    return summary;
  }

  const std::vector<Eigen::Isometry3d>& estimate() const { return estimate_; }
  std::size_t edge_count() const { return edge_count_; }

 private:
  struct ActiveLoop {
    PoseGraphEdge edge;
    std::size_t record = 0;
  };

  // The active loop closure whose residual at `poses` exceeds the limits by the largest factor,
  // or loops_.size() when all are within them.
  std::size_t least_consistent_loop(const std::vector<Eigen::Isometry3d>& poses,
                                    const std::vector<bool>& dropped) const {
    std::size_t worst = loops_.size();
    double worst_excess = 1.0;
    for (std::size_t l = 0; l < loops_.size(); ++l) {
      if (dropped[l]) continue;
      const PoseGraphEdge& edge = loops_[l].edge;
      const EdgeResidual residual = measured_residual(edge, poses);
      const double limit_m = consistency_.max_residual_m +
                             consistency_.baseline_fraction * edge.measurement.translation().norm();
      const double excess = std::max(residual.metres / limit_m,
                                     residual.radians / (consistency_.max_residual_deg * kDegree));
      if (excess > worst_excess) {
        worst_excess = excess;
        worst = l;
      }
    }
    return worst;
  }
  PoseGraphParams options_;
  LoopConsistency consistency_;
  std::vector<Eigen::Isometry3d> estimate_;
  std::vector<ActiveLoop> loops_;
  std::size_t anchor_ = 0;
  Eigen::Isometry3d anchor_estimate_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d anchor_odometry_ = Eigen::Isometry3d::Identity();
  std::size_t edge_count_ = 0;
};

// The loop-closure candidates of the newest keyframe, by pose and by appearance (a match found
// both ways is verified once, from the pose estimate), each verified; the accepted ones join the
// graph. A keyframe the odometry lost (a fallback) is relocalised: any earlier keyframe may match
// it by appearance. Returns whether any was accepted.
bool close_loops(LoopClosureDetector& detector, GraphState& state,
                 std::span<const registration::RelativePose> odometry_steps, bool lost,
                 const SlamObserver& observer, SlamResult& result) {
  const std::size_t query = detector.keyframe_count() - 1;
  std::vector<LoopCandidate> candidates = detector.find_candidates(query, state.estimate());
  for (const LoopCandidate& c :
       detector.find_appearance_candidates(query, state.estimate(), lost)) {
    ++result.appearance_candidates;
    const bool known =
        std::any_of(candidates.begin(), candidates.end(),
                    [&](const LoopCandidate& other) { return other.match == c.match; });
    if (!known) candidates.push_back(c);
  }
  // How far the estimate between the two keyframes could have drifted: the odometry chain's.
  const LoopClosureDetector::ExpectedUncertainty uncertainty = [&](const LoopCandidate& c) {
    return chain_covariance(odometry_steps, state.estimate(), c.match_frame, c.query_frame);
  };
  bool closed = false;
  for (const LoopCandidate& candidate : candidates) {
    ++result.loop_candidates;
    LoopClosure closure = detector.verify(candidate, state.estimate(), uncertainty);
    if (observer.on_loop_closure) observer.on_loop_closure(closure);
    if (closure.report.accepted()) {
      state.add_loop(closure, result.loop_closures.size());
      closed = true;
    }
    result.loop_closures.push_back({std::move(closure), false});
  }
  return closed;
}

}  // namespace

OdometryRun run_odometry(const compute::Context& context, const FrameSource& source,
                         const registration::OdometryParams& params, const SlamObserver& observer,
                         const ModelTrackingParams& model) {
  Tracker tracker(context, source.camera(), source.depth_units_per_metre(), params, model);
  const std::size_t total = source.size();
  const FrameLoopTiming timing =
      for_each_frame(source, 0, total, [&](std::size_t i, registration::RgbdImages& images) {
        const registration::OdometryFrame& frame = tracker.track(images);
        if (observer.on_frame) observer.on_frame(frame);
        if (observer.on_progress) observer.on_progress("odometry", i + 1, total);
      });
  return tracker.finish(timing);
}

struct OnlineSlam::State {
  State(const compute::Context& context, const PinholeIntrinsics& camera, double units,
        const SlamParams& params, const SlamObserver& observer)
      : tracker(context, camera, units, params.odometry, params.model),
        graph(params.graph, params.consistency),
        observer(observer),
        reestimate_interval(
            static_cast<std::size_t>(tracker.odometry().params().reestimate_interval)) {
    if (params.loop_closure) {
      detector.emplace(context, camera, tracker.odometry().params().depth_range, params.loops,
                       params.features);
    }
  }

  void optimise() {
    const auto start = Clock::now();
    result.final_graph =
        graph.optimise(tracker.constraints(), tracker.poses(), result.loop_closures);
    ++result.graph_optimisations;
    result.timing.optimisation_seconds += seconds_since(start);
  }

  // Each accepted loop closure's chi^2 and residual at the final poses.
  void describe_loops() {
    PoseGraph final_poses{result.poses, {}};
    for (LoopClosureRecord& record : result.loop_closures) {
      if (!record.closure.report.accepted()) continue;
      const PoseGraphEdge edge = edge_of(record.closure.constraint, true);
      record.chi2 = edge_chi2(final_poses, edge);
      const EdgeResidual residual = measured_residual(edge, result.poses);
      record.residual_m = residual.metres;
      record.residual_deg = residual.radians / kDegree;
    }
  }

  Tracker tracker;
  GraphState graph;
  SlamObserver observer;
  std::size_t reestimate_interval;
  std::optional<LoopClosureDetector> detector;
  SlamResult result;
  bool finished = false;
};

OnlineSlam::OnlineSlam(const compute::Context& context, const PinholeIntrinsics& camera,
                       double depth_units_per_metre, const SlamParams& params,
                       const SlamObserver& observer)
    : state_(std::make_unique<State>(context, camera, depth_units_per_metre, params, observer)) {}

OnlineSlam::~OnlineSlam() = default;
OnlineSlam::OnlineSlam(OnlineSlam&&) noexcept = default;
OnlineSlam& OnlineSlam::operator=(OnlineSlam&&) noexcept = default;

SlamStep OnlineSlam::add(const registration::RgbdImages& images) {
  State& s = *state_;
  require(!s.finished, "online SLAM: a frame was added after finish()");
  const std::size_t i = s.tracker.odometry().frame_count();
  const registration::OdometryFrame& frame = s.tracker.track(images);
  s.graph.follow(s.tracker.poses(), s.reestimate_interval);
  if (s.observer.on_frame) s.observer.on_frame(frame);
  SlamStep step;
  step.frame = i;
  step.odometry = frame;
  if (s.detector && frame.keyframe) {
    const auto start = Clock::now();
    s.detector->add_keyframe(i, images.depth, s.tracker.path_length(i), color_of(images));
    step.optimised = close_loops(*s.detector, s.graph, s.tracker.constraints(), frame.fallback,
                                 s.observer, s.result);
    s.result.timing.loop_closure_seconds += seconds_since(start);
    if (step.optimised) s.optimise();
  }
  step.pose = s.graph.estimate()[i];
  return step;
}

std::size_t OnlineSlam::frame_count() const {
  return state_->tracker.odometry().frame_count();
}

const std::vector<Eigen::Isometry3d>& OnlineSlam::poses() const {
  return state_->graph.estimate();
}

std::size_t OnlineSlam::keyframe_bytes_in_memory() const {
  return state_->detector ? state_->detector->keyframe_bytes_in_memory() : 0;
}

std::size_t OnlineSlam::keyframe_bytes_on_disk() const {
  return state_->detector ? state_->detector->keyframe_bytes_on_disk() : 0;
}

SlamResult OnlineSlam::finish() {
  State& s = *state_;
  require(!s.finished, "online SLAM: finish() was called twice");
  s.finished = true;
  s.result.odometry = s.tracker.finish();
  // Tracking's time: the odometry's, and the model's ray casts, registrations and fusion.
  s.result.timing.odometry_seconds =
      s.result.odometry.compute_seconds + s.result.odometry.model_seconds;
  if (frame_count() > 0) s.optimise();
  s.result.poses = s.graph.estimate();
  s.result.graph_edges = s.graph.edge_count();
  s.describe_loops();
  return std::move(s.result);
}

}  // namespace kartograf::mapping
