#include "kartograf/mapping/slam.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <numbers>
#include <optional>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kDegree = std::numbers::pi / 180.0;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

registration::OdometryParams with_source_units(registration::OdometryParams params,
                                               const FrameSource& source) {
  params.depth_range.units_per_metre = source.depth_units_per_metre();
  return params;
}

const RgbImage* color_of(const registration::RgbdImages& images) {
  return images.color.empty() ? nullptr : &images.color;
}

void report_progress(const SlamObserver& observer, std::string_view stage, std::size_t done,
                     std::size_t total) {
  if (observer.on_progress) observer.on_progress(stage, done, total);
}

// Tracks every frame of a source, keeping what both runs report.
class Tracker {
 public:
  Tracker(const compute::Context& context, const FrameSource& source,
          const registration::OdometryParams& params, const ModelTrackingParams& model = {})
      : odometry_(context, source.camera(), with_source_units(params, source)) {
    if (model.enabled) {
      model_.emplace(context, source.camera(), odometry_.params().depth_range, model);
      run_.model_tracking = true;
    }
  }

  const registration::OdometryFrame& track(const registration::RgbdImages& images) {
    run_.timestamps.push_back(images.timestamp);
    const registration::OdometryFrame& frame = odometry_.track(images.depth, color_of(images));
    run_.compute_seconds += frame.seconds;
    if (model_) track_model(images);
    const auto& poses = odometry_.poses();
    const std::size_t n = poses.size() - 1;
    path_.push_back(
        n == 0 ? 0.0 : path_.back() + (poses[n].translation() - poses[n - 1].translation()).norm());
    return frame;
  }

  const registration::RgbdOdometry& odometry() const { return odometry_; }
  double path_length(std::size_t frame) const { return path_[frame]; }

  OdometryRun finish(const FrameLoopTiming& timing) {
    run_.poses = model_ ? model_poses_ : odometry_.poses();
    run_.frames = odometry_.frames();
    run_.constraints = odometry_.constraints();
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
    const ModelTrackingStep step = model_->track(images.depth, color_of(images), predicted);
    model_poses_.push_back(step.pose);
    run_.model_kept += step.from_model ? 1 : 0;
    run_.model_seconds += seconds_since(start);
  }

  registration::RgbdOdometry odometry_;
  std::optional<ModelTracker> model_;
  std::vector<Eigen::Isometry3d> model_poses_;
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

// The colour of each pyramid pixel: the top-left pixel of its 2^level x 2^level block (the
// pyramid averages depth; colour from an unregistered camera is only approximately aligned anyway).
void colors_at_level(const RgbImage& color, int level, int width, int height, RgbImage& out) {
  // The frame source checks colour against depth; a source that does not must not read past
  // the colour image.
  require(width > 0 && height > 0 && ((width - 1) << level) < color.width() &&
              ((height - 1) << level) < color.height(),
          "colour image is " + std::to_string(color.width()) + "x" +
              std::to_string(color.height()) + ", smaller than the depth camera's pixel grid (" +
              std::to_string(width << level) + "x" + std::to_string(height << level) + ")");
  if (out.width() != width || out.height() != height) out = RgbImage(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) out(u, v) = color(u << level, v << level);
  }
}

// Second pass: every frame's points and normals at its pose (pose_of(i, images); a pose given
// with the frames is resolved while they are read).
PointCloud fuse_map(
    const compute::Context& context, const FrameSource& source, std::size_t frames,
    const std::function<Eigen::Isometry3d(std::size_t, const registration::RgbdImages&)>& pose_of,
    const SlamParams& params, const SlamObserver& observer, SlamResult& result) {
  const registration::OdometryParams odometry = with_source_units(params.odometry, source);
  registration::RgbdPyramidBuilder builder(context, source.camera(), odometry.depth_range);
  // The level at most 320 pixels wide (half resolution of 640x480): averaged points with
  // smoother normals, a quarter of the work.
  const int level = registration::pyramid_level_at_most(source.camera().width, 320);
  registration::PyramidParams pyramid;
  pyramid.levels = level + 1;
  registration::FramePyramid frame(context, source.camera(), pyramid);
  MapFusion fusion(params.map);
  RgbImage level_colors;
  double fusing = 0;
  const FrameLoopTiming timing =
      for_each_frame(source, 0, frames, [&](std::size_t i, registration::RgbdImages& images) {
        const Eigen::Isometry3d pose = pose_of(i, images);
        const auto start = Clock::now();
        builder.build(images.depth, nullptr, frame);
        const registration::PyramidLevel& fused = frame.level(level);
        const PointImage points = fused.points.to_image();
        const NormalImage normals = fused.normals.to_image();
        const RgbImage* color = color_of(images);
        if (color) colors_at_level(*color, level, points.width(), points.height(), level_colors);
        fusion.add(points, normals, color ? &level_colors : nullptr, pose);
        fusing += seconds_since(start);
        report_progress(observer, "map", i + 1, frames);
      });
  result.timing.map_seconds = fusing;
  result.timing.load_seconds += timing.load_seconds;
  result.map_voxels = fusion.voxel_count();
  return fusion.cloud();
}

// The loop-closure candidates of the newest keyframe, by pose and by appearance (a match found
// both ways is verified once, from the pose estimate), each verified; the accepted ones join the
// graph. A keyframe the odometry lost (a fallback) is relocalised: any earlier keyframe may match
// it by appearance. Returns whether any was accepted.
bool close_loops(LoopClosureDetector& detector, GraphState& state, bool lost,
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
  bool closed = false;
  for (const LoopCandidate& candidate : candidates) {
    ++result.loop_candidates;
    LoopClosure closure = detector.verify(candidate, state.estimate());
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

PoseGraphParams slam_graph_options() {
  PoseGraphParams options;
  options.loop_closure_kernel = 0;
  options.prune_chi2 = 0;
  return options;
}

OdometryRun run_odometry(const compute::Context& context, const FrameSource& source,
                         const registration::OdometryParams& params, const SlamObserver& observer,
                         const ModelTrackingParams& model) {
  Tracker tracker(context, source, params, model);
  const std::size_t total = source.size();
  const FrameLoopTiming timing =
      for_each_frame(source, 0, total, [&](std::size_t i, registration::RgbdImages& images) {
        const registration::OdometryFrame& frame = tracker.track(images);
        if (observer.on_frame) observer.on_frame(frame);
        report_progress(observer, "odometry", i + 1, total);
      });
  return tracker.finish(timing);
}

SlamResult run_slam(const compute::Context& context, const FrameSource& source,
                    const SlamParams& params, const SlamObserver& observer) {
  const auto start = Clock::now();
  SlamResult result;
  Tracker tracker(context, source, params.odometry);
  std::optional<LoopClosureDetector> detector;
  const registration::OdometryParams& odometry_params = tracker.odometry().params();
  if (params.loop_closure) {
    detector.emplace(context, source.camera(), odometry_params.depth_range, params.loops,
                     params.features);
  }
  GraphState state(params.graph, params.consistency);
  const auto reestimate_interval = static_cast<std::size_t>(odometry_params.reestimate_interval);
  const std::size_t total = source.size();

  const auto optimise = [&] {
    const auto optimise_start = Clock::now();
    result.final_graph = state.optimise(tracker.odometry().constraints(),
                                        tracker.odometry().poses(), result.loop_closures);
    ++result.graph_optimisations;
    result.timing.optimisation_seconds += seconds_since(optimise_start);
  };

  const FrameLoopTiming timing =
      for_each_frame(source, 0, total, [&](std::size_t i, registration::RgbdImages& images) {
        const registration::OdometryFrame& frame = tracker.track(images);
        state.follow(tracker.odometry().poses(), reestimate_interval);
        if (observer.on_frame) observer.on_frame(frame);
        if (detector && frame.keyframe) {
          const auto loop_start = Clock::now();
          detector->add_keyframe(i, images.depth, tracker.path_length(i), color_of(images));
          const bool closed = close_loops(*detector, state, frame.fallback, observer, result);
          result.timing.loop_closure_seconds += seconds_since(loop_start);
          if (closed) optimise();
        }
        report_progress(observer, "odometry", i + 1, total);
      });
  result.odometry = tracker.finish(timing);
  result.timing.odometry_seconds = result.odometry.compute_seconds;
  result.timing.load_seconds = timing.load_seconds;

  if (total > 0) optimise();
  result.poses = state.estimate();
  result.graph_edges = state.edge_count();
  PoseGraph final_poses{result.poses, {}};
  for (LoopClosureRecord& record : result.loop_closures) {
    if (!record.closure.report.accepted()) continue;
    const PoseGraphEdge edge = edge_of(record.closure.constraint, true);
    record.chi2 = edge_chi2(final_poses, edge);
    const EdgeResidual residual = measured_residual(edge, result.poses);
    record.residual_m = residual.metres;
    record.residual_deg = residual.radians / kDegree;
  }
  if (params.build_map && total > 0) {
    const auto optimised = [&](std::size_t i, const registration::RgbdImages&) {
      return result.poses[i];
    };
    result.map = fuse_map(context, source, total, optimised, params, observer, result);
  }
  result.timing.total_seconds = seconds_since(start);
  return result;
}

SlamResult run_with_known_poses(const compute::Context& context, const FrameSource& source,
                                const KnownPoseLookup& pose_of, const SlamParams& params,
                                const SlamObserver& observer) {
  require(static_cast<bool>(pose_of), "slam with known poses: no pose lookup given");
  const auto start = Clock::now();
  SlamResult result;
  result.poses_given = true;
  std::optional<Eigen::Isometry3d> first_inverse;
  // Expressed relative to the first frame, as estimated trajectories are.
  const auto relative_pose = [&](std::size_t i, const registration::RgbdImages& images) {
    const Eigen::Isometry3d pose = pose_of(i, images);
    require(pose.matrix().allFinite() &&
                (pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity())
                        .cwiseAbs()
                        .maxCoeff() < 1e-3,
            "slam with known poses: the pose of frame " + std::to_string(i) +
                " is not finite or not a rotation");
    if (!first_inverse) first_inverse = pose.inverse();
    const Eigen::Isometry3d relative = *first_inverse * pose;
    result.poses.push_back(relative);
    result.odometry.timestamps.push_back(images.timestamp);
    return relative;
  };
  if (params.build_map) {
    result.map = fuse_map(context, source, source.size(), relative_pose, params, observer, result);
  } else {
    result.timing.load_seconds =
        for_each_frame(source, 0, source.size(), [&](std::size_t i, registration::RgbdImages& im) {
          relative_pose(i, im);
        }).load_seconds;
  }
  result.odometry.poses = result.poses;
  result.timing.total_seconds = seconds_since(start);
  return result;
}

}  // namespace kartograf::mapping
