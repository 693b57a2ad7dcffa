#pragma once
// The RGB-D SLAM pipeline (docs/methods.md M3 and the paper's future work): odometry with the
// paper's drift reduction (re-estimates against an anchor), loop closure between keyframes, a pose
// graph over every frame, and a fused map. Wiring only: the parts are registration/odometry.hpp,
// mapping/loop_closure.hpp, mapping/pose_graph.hpp and mapping/map_fusion.hpp; frames come through
// a FrameSource, read one ahead on a second thread.
//
//   1. Every frame is tracked by RgbdOdometry. The pose graph has one node per frame and one edge
//      per accepted registration (frame-to-frame and anchor re-estimates, information from the
//      frame's geometric information through the InformationModel) or motion-model fallback (a weak
//      prior).
//   2. Each new keyframe is matched against earlier keyframes (LoopClosureDetector with the
//      current estimate). Verified loop closures become edges; after a keyframe that closed a
//      loop the graph is optimised, so that later candidates are searched with the corrected
//      poses (the frames after it follow by their odometry).
//   3. At the end the whole graph is optimised once more. Loop closures inconsistent with the
//      optimised poses (LoopConsistency) are pruned, the worst first, and reported.
//   4. A second pass over the frames fuses them at their optimised poses (MapFusion).
#include <cstddef>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/mapping/frame_source.hpp"
#include "kartograf/mapping/loop_closure.hpp"
#include "kartograf/mapping/map_fusion.hpp"
#include "kartograf/mapping/model_tracking.hpp"
#include "kartograf/mapping/pose_graph.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::mapping {

// After an optimisation, a loop closure whose edge still disagrees with the poses by more than
// this, in the directions it measured (those its information constrains), is inconsistent with
// the rest: dropped (the worst first) and the graph optimised again.
// The translation limit grows with the loop's own translation: wide-baseline registrations carry
// a systematic error (loop_closure.hpp's baseline_error_fraction; on 7-Scenes right loops were
// 2-9 cm off the truth at baselines of 0.35-0.65 m) that a fixed limit takes for a wrong loop.
struct LoopConsistency {
  double max_residual_m = 0.03;
  double baseline_fraction = 0.05;  // of the loop's translation, added to max_residual_m
  double max_residual_deg = 2;
};

// Verified loop closures are trusted in the least squares (no robust kernel, no chi^2 pruning):
// ICP's information describes random errors, and odometry also drifts systematically, so a
// correct loop closing 8 cm of drift would otherwise look like an outlier. Inconsistent ones are
// removed by LoopConsistency instead.
PoseGraphParams slam_graph_options();

struct SlamParams {
  registration::OdometryParams odometry;
  bool loop_closure = true;
  LoopClosureParams loops;
  // Local features (optional; the features layer's OrbFrontEnd): loop-closure candidates by
  // appearance, and the odometry's recovery from a lost frame.
  std::shared_ptr<const registration::FeatureFrontEnd> features;
  PoseGraphParams graph = slam_graph_options();
  LoopConsistency consistency;
  // Frame-to-model tracking (model.enabled): the graph's odometry poses and edges are the
  // model's, predicted by params.odometry's frame-to-frame odometry (ModelTrackingParams::
  // predicting).
  ModelTrackingParams model;
  bool build_map = true;
  MapFusionParams map;
};

// Optional callbacks, called on the caller's thread.
struct SlamObserver {
  std::function<void(const registration::OdometryFrame&)> on_frame;  // after each tracked frame
  std::function<void(const LoopClosure&)> on_loop_closure;           // after each verification
  // stage: "odometry" or "map"; done of total frames.
  std::function<void(std::string_view stage, std::size_t done, std::size_t total)> on_progress;
};

struct OdometryRun {
  std::vector<double> timestamps;        // the source's
  std::vector<Eigen::Isometry3d> poses;  // camera-to-world, frame 0 = identity
  std::vector<registration::OdometryFrame> frames;
  std::vector<registration::RelativePose> constraints;
  std::vector<std::size_t> keyframes;
  FrameLoopTiming timing;      // wall time with frame loading, load time, waits
  double compute_seconds = 0;  // sum of OdometryFrame::seconds: the run without file I/O
  // With model tracking: poses are the model's (frame-to-frame odometry predicts them), and
  // how many frames kept the model's registration.
  bool model_tracking = false;
  std::size_t model_kept = 0;
  // Frames whose model, full, evicted the blocks least recently seen (evict_fill).
  std::size_t model_evictions = 0;
  double model_seconds = 0;  // ray casting, registration and fusion
};

// Odometry alone over the whole source.
// With model.enabled, each frame is then tracked against the model (model_tracking.hpp).
OdometryRun run_odometry(const compute::Context& context, const FrameSource& source,
                         const registration::OdometryParams& params,
                         const SlamObserver& observer = {}, const ModelTrackingParams& model = {});

struct LoopClosureRecord {
  LoopClosure closure;
  bool pruned = false;  // accepted, then removed by the pose graph as inconsistent
  // Accepted ones, at the final poses: chi^2 of the edge, and how far the poses disagree with it
  // in the directions it measured.
  double chi2 = 0;
  double residual_m = 0;
  double residual_deg = 0;
};

struct SlamTimings {
  double odometry_seconds = 0;  // tracking, without file I/O
  double loop_closure_seconds = 0;
  double optimisation_seconds = 0;
  double map_seconds = 0;   // fusion, without file I/O
  double load_seconds = 0;  // reading frames (both passes, on the prefetch thread)
  double total_seconds = 0;
};

struct SlamResult {
  OdometryRun odometry;                          // the odometry's own estimate and reports
  std::vector<Eigen::Isometry3d> poses;          // optimised, camera-to-world, frame 0 = identity
  std::vector<LoopClosureRecord> loop_closures;  // every verified candidate
  std::size_t loop_candidates = 0;               // verified, by pose or by appearance
  std::size_t appearance_candidates = 0;         // found by appearance (some also by pose)
  std::size_t graph_optimisations = 0;
  PoseGraphSummary final_graph;  // the last optimisation
  std::size_t graph_edges = 0;   // after pruning
  PointCloud map;                // empty unless build_map
  bool poses_given = false;      // run_with_known_poses: nothing was estimated
  std::size_t map_voxels = 0;    // before the min_points filter
  SlamTimings timing;
};

SlamResult run_slam(const compute::Context& context, const FrameSource& source,
                    const SlamParams& params, const SlamObserver& observer = {});

// A trajectory known beforehand (ground truth, another system's estimate): camera-to-world pose
// of frame i (its images carry its timestamp and any ground truth); throws Error when it has none.
using KnownPoseLookup =
    std::function<Eigen::Isometry3d(std::size_t frame, const registration::RgbdImages& images)>;

// The map from known poses, nothing estimated: poses (and odometry.poses) are pose_of's,
// expressed relative to the first frame; the map is fused as run_slam's. Throws Error on a pose
// that is not finite or not a rotation.
SlamResult run_with_known_poses(const compute::Context& context, const FrameSource& source,
                                const KnownPoseLookup& pose_of, const SlamParams& params,
                                const SlamObserver& observer = {});

}  // namespace kartograf::mapping
