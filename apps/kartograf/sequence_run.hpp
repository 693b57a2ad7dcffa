#pragma once
// What `kartograf odometry` and `kartograf slam` share: options, opening the sequence, the compute
// context, a progress bar, warnings about rejected registrations, trajectories in TUM format and
// scoring against ground truth (the stats documents: kartograf/outputs/odometry_stats.hpp). Wiring
// only.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/trajectory.hpp"
#include "kartograf/eval/ground_truth_sampling.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/outputs/odometry_stats.hpp"
#include "kartograf/outputs/prior_clock.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::cli {

// The most frames a frame option takes (--first, --frames): far beyond any recording.
inline constexpr std::uint64_t kMaxFrames = 100000000;

// Registers --camera, --skip-bad-frames, with_depth_scale --depth-scale and, with_range, --first,
// --frames, --step (a command that has some of them already registers them itself).
void add_sequence_input_options(CLI::App& command, SequenceInputOptions& options, bool with_range,
                                bool with_depth_scale);
// Registers SEQUENCE, the input options, --method, --backend, --reestimate-every, --no-progress.
void add_sequence_run_options(CLI::App& command, SequenceRunOptions& options);

io::SequenceParams sequence_options(const SequenceInputOptions& options);
// Opens a sequence folder as the options say; on err: warnings (a camera assumed), each frame left
// out, and one line with the frame count, the camera and the depth scale. Then the first frames'
// depth is checked against `range` (at the sequence's depth scale): a wrong scale is an error
// before any command's work (pipeline::check_depth_usable).
io::OpenedSequence open_input(const std::filesystem::path& folder,
                              const SequenceInputOptions& options, std::ostream& err,
                              const geometry::DepthRange& range = {});
registration::OdometryParams odometry_params(const SequenceRunOptions& options);
// A warning on err when the semantic grid's cells are not the 0.05 m its thresholds were set for
// (its walls and doors are less reliable there; docs/user-guide.md, "Grid resolution").
void warn_untuned_grid_resolution(const std::string& command, double resolution, std::ostream& err);
compute::Context make_run_context(const SequenceRunOptions& options);
// --tracking and --model-voxel.
mapping::ModelTrackingParams model_tracking_params(const SequenceRunOptions& options);
// The summary's line on model tracking (empty without it): frames that kept the model's pose,
// its time per frame and how often a full model evicted blocks.
std::string model_tracking_line(const mapping::OdometryRun& run);
// The options and the context as the stats documents record them.
io::SequenceRunRecord run_record(const SequenceRunOptions& options,
                                 const compute::Context& context);

// The opened sequence and the pipeline's view of it.
struct OpenedRun {
  io::OpenedSequence opened;
  std::unique_ptr<pipeline::SequenceFrameSource> source;
  Eigen::Isometry3d pose_mount = Eigen::Isometry3d::Identity();  // --pose-mount
  // The --motion-prior FILE's poses, sorted by time (null without one), and the offset its clock
  // is read at (--prior-time-offset, or as calibrate_prior_clock measured it).
  std::shared_ptr<const Trajectory> prior_poses;
  double prior_time_offset = 0;
};
// --pose-mount checked against `poses` (the command's --poses, if it has one) and the motion
// prior, open_input (the first frames' depth checked against the odometry's depth range),
// --prior-time-offset refused without a prior file or timestamps, and --method color or planar
// refused on a sequence without colour.
OpenedRun open_run(const SequenceRunOptions& options, std::ostream& err,
                   const std::string& poses = {});

// Error naming `what` and the folder when the sequence has no colour images (a depth camera
// alone), before any work.
void require_colour(const io::OpenedSequence& opened, const std::filesystem::path& folder,
                    const std::string& what);

// A bar on a terminal (redrawn in place), else a line every 10 %.
class ProgressBar {
 public:
  ProgressBar(std::ostream& err, bool enabled);
  void update(std::string_view stage, std::size_t done, std::size_t total);
  void finish();  // ends the bar's line

 private:
  std::ostream* err_;
  bool enabled_;
  bool terminal_;
  std::string stage_;
  int last_step_ = -1;
  bool open_line_ = false;
  std::chrono::steady_clock::time_point stage_start_;
};

// A warning line on `err` for each rejected registration or fallback of a frame.
void warn_about(std::ostream& err, ProgressBar& bar, const registration::OdometryFrame& frame);

// What odometry, slam and map report while tracking: warn_about per frame, progress on `bar`.
mapping::SlamObserver slam_progress_observer(std::ostream& err, ProgressBar& bar);

// Timestamps: the sequence's, or the frame number where it has none (7-Scenes).
Trajectory stamped_trajectory(const std::vector<Eigen::Isometry3d>& poses,
                              const std::vector<double>& timestamps, bool has_timestamps);
// The ground truth of the frames that have one, stamped like the estimate.
Trajectory ground_truth_trajectory(const pipeline::SequenceFrameSource& source,
                                   const std::vector<double>& timestamps, bool has_timestamps);
// ATE (SE(3) alignment) of the estimate's frames that have ground truth; empty without any.
std::optional<eval::AteResult> absolute_trajectory_error(
    const pipeline::SequenceFrameSource& source, const std::vector<Eigen::Isometry3d>& poses);
// The same at the ground truth's measured poses alone, where it interpolates between them (SUN3D's
// every 5th frame; eval/ground_truth_sampling.hpp); empty where it measured every pose.
std::optional<eval::MeasuredPoseAte> ate_at_measured_poses(
    const pipeline::SequenceFrameSource& source, const std::vector<Eigen::Isometry3d>& poses);
// "  ground truth measured every N frames, interpolated between: ate_rmse_m X at its M measured
// poses" and a newline.
std::string measured_poses_line(const eval::MeasuredPoseAte& measured);

// Registers --pose-mount (odometry, slam and map register it with the run options; fuse itself).
void add_pose_mount_option(CLI::App& command, std::vector<double>& mount);
// The camera's pose in the pose files' body (identity without --pose-mount); an Error naming the
// option for a quaternion that is not a unit one, or where no --poses or --motion-prior FILE is
// given for it to apply to.
Eigen::Isometry3d pose_mount(const SequenceRunOptions& options, const std::string& poses);

// --poses of `map` and `fuse` (and --motion-prior, `option`): each frame's pose from the
// sequence's ground truth ("groundtruth") or from a TUM file at the frame's timestamp (pose_at:
// interpolated; at the timestamp plus `time_offset`, the file's clock's lead), or at its frame
// number where the layout has no timestamps, times `mount` (a file's body to the camera); a frame
// without one stops the run with an Error naming `command`, `option` and the frame.
mapping::KnownPoseLookup known_pose_lookup(
    const std::string& command, const std::string& poses, bool by_frame_number,
    const std::string& option = "--poses",
    const Eigen::Isometry3d& mount = Eigen::Isometry3d::Identity(), double time_offset = 0);
// A TUM pose file sorted by time; an Error naming `named` and the file where it holds no pose.
std::shared_ptr<const Trajectory> read_pose_file(const std::string& named, const std::string& file);
// known_pose_lookup's rule over a file read already (`poses`: its name, for the errors).
mapping::KnownPoseLookup pose_file_lookup(const std::string& named,
                                          std::shared_ptr<const Trajectory> trajectory,
                                          const std::string& poses, bool by_frame_number,
                                          const Eigen::Isometry3d& mount, double time_offset);

// How well the --motion-prior FILE's turning agrees with the estimated trajectory's, at the
// offset in use and at the best one (eval::estimate_clock_offset); none without a prior file or
// timestamps.
std::optional<io::PriorClock> measure_prior_clock(const OpenedRun& run,
                                                  const std::vector<Eigen::Isometry3d>& poses,
                                                  const std::vector<double>& timestamps);
// --prior-time-offset auto: the odometry over the first 600 frames without the prior, the
// clock's offset measured from it (said on err) and the run's prior read at it from then on; an
// Error where the motion cannot tell it. Nothing otherwise.
void calibrate_prior_clock(const SequenceRunOptions& options, const compute::Context& context,
                           OpenedRun& run, std::ostream& err);
// "  motion prior clock: ..." (io::prior_clock_text) and a newline; empty without one.
std::string prior_clock_line(const std::optional<io::PriorClock>& clock);

}  // namespace kartograf::cli
