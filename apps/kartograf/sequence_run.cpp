#include "sequence_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <iterator>
#include <memory>

#include "backend_option.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/trajectory.hpp"
#include "kartograf/formats/tum.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"
#include "kartograf/pipeline/tracking_choices.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "option_checks.hpp"

namespace kartograf::cli {

void add_sequence_input_options(CLI::App& command, SequenceInputOptions& o, bool with_range,
                                bool with_depth_scale) {
  std::string presets;
  for (const std::string& name : io::camera_preset_names())
    presets += (presets.empty() ? "" : "|") + name;
  command.add_option("--camera", o.camera,
                     "Camera intrinsics: a preset (" + presets +
                         "), fx,fy,cx,cy, or a file (camera-intrinsics.txt with a 3x3 matrix, "
                         "Open3D camera_intrinsics.json); default: the folder's own");
  if (with_depth_scale) {
    command
        .add_option("--depth-scale", o.depth_scale,
                    "Depth units per metre (1000: millimetres, 5000: TUM); default: the layout's")
        ->check(CLI::PositiveNumber);
  }
  command.add_flag("--skip-bad-frames", o.skip_bad_frames,
                   "Leave out missing or unreadable frames (each reported) instead of stopping");
  if (!with_range) return;
  command.add_option("--first", o.first, "First frame (0: the folder's first, in its order)")
      ->check(whole_number(kMaxFrames));
  command.add_option("--frames", o.frames, "Use at most N frames (0: all)")
      ->check(whole_number(kMaxFrames));
  command.add_option("--step", o.step, "Use every S-th frame")->check(CLI::Range(1, 1000000));
}

void add_sequence_run_options(CLI::App& command, SequenceRunOptions& o) {
  command
      .add_option("SEQUENCE", o.sequence,
                  "RGB-D sequence folder: TUM (rgb.txt, depth.txt), kartograf synth, 7-Scenes / "
                  "3DMatch / SUN3D (frame-N.*), or rgb/ + depth/ folders")
      ->required();
  add_sequence_input_options(command, o.input, true, true);
  command.add_option("--method", o.method, "ICP error metric and pair rejection")
      ->check(CLI::IsMember({"p2p", "p2plane", "color", "planar"}))
      ->capture_default_str();
  add_backend_option(command, o.backend, o.backend_source);
  command
      .add_option("--tracking", o.tracking,
                  "frame: frame-to-frame odometry; model: each frame registered against the "
                  "TSDF of the frames before it (KinectFusion's frame-to-model tracking), from "
                  "the prediction of a frame-to-frame odometry at 160 pixels wide without "
                  "re-estimates (slam, map: the pose graph's odometry is the model's)")
      ->check(CLI::IsMember({"frame", "model"}))
      ->capture_default_str();
  command.add_option("--model-voxel", o.model_voxel, "Voxel size of the model [m]")
      ->check(CLI::Range(0.005, 0.2))
      ->capture_default_str();
  command
      .add_option("--reestimate-every", o.reestimate_interval,
                  "Re-register every k-th frame against the anchor (the M3 paper's drift "
                  "reduction; 0: off; --tracking model: off)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  command
      .add_option(
          "--anchor-bounds", o.anchor_bounds,
          "The re-estimates' anchor is kept while the next re-estimate is within M "
          "metres, DEG degrees and FRAMES frames of it (0,0,0: frame n-k, the paper's rule)")
      ->expected(3)
      ->delimiter(',')
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  command.add_option(
      "--motion-prior", o.motion_prior,
      "Another sensor's camera poses (a TUM trajectory, e.g. a wheeled robot's "
      "odometry through the camera mount; at each frame's timestamp, interpolated "
      "between two poses at most 0.5 s apart, else the nearest within 20 ms; "
      "'groundtruth': the sequence's own, an ideal one): each step is predicted from "
      "them instead of the motion model, and views that leave a direction free "
      "(a plain wall, a corridor) take their motion there");
  command
      .add_option_function<std::string>(
          "--prior-time-offset",
          [&o](const std::string& value) {
            o.prior_time_offset_auto = value == "auto";
            o.prior_time_offset = o.prior_time_offset_auto ? 0.0 : std::stod(value);
          },
          "Seconds the --motion-prior FILE's clock is ahead of the frames' timestamps (its pose "
          "for a frame is read at the frame's time plus this), -10..10; auto: measured first "
          "from how the camera turns over the first 20 s without the prior (the summary's "
          "'motion prior clock' line measures it after any run)")
      ->check(finite_in(-10.0, 10.0) | CLI::IsMember({"auto"}));
  add_pose_mount_option(command, o.pose_mount);
  command.add_flag("!--no-progress", o.progress, "No progress bar on stderr");
}

io::SequenceParams sequence_options(const SequenceInputOptions& o) {
  io::SequenceParams options;
  options.camera = o.camera;
  if (o.depth_scale > 0) options.depth_units_per_metre = o.depth_scale;
  options.first = o.first;
  if (o.frames > 0) options.count = o.frames;
  options.step = o.step;
  options.skip_bad_frames = o.skip_bad_frames;
  return options;
}

io::OpenedSequence open_input(const std::filesystem::path& folder, const SequenceInputOptions& o,
                              std::ostream& err, const geometry::DepthRange& range) {
  io::OpenedSequence opened = io::open_sequence(folder, sequence_options(o));
  for (const std::string& warning : opened.warnings) err << "warning: " << warning << "\n";
  for (const io::SkippedFrame& skipped : opened.skipped)
    err << "warning: frame " << skipped.position << " left out: " << skipped.reason << "\n";
  err << "input: " << opened.sequence->size() << " frames";
  if (!opened.skipped.empty()) err << " (" << opened.skipped.size() << " bad frames left out)";
  err << "; " << io::describe_input(opened) << "\n";
  pipeline::check_depth_usable(*opened.sequence, range);
  return opened;
}

void warn_untuned_grid_resolution(const std::string& command, double resolution,
                                  std::ostream& err) {
  // The default cell size is the one the thresholds were set for.
  const double tuned = semantic::SemanticGridParams{}.resolution;
  if (std::fabs(resolution - tuned) <= 1e-9) return;
  err << command << ": warning: --resolution " << resolution
      << " m: the semantic grid's thresholds are set for " << tuned
      << " m cells, and at other sizes its "
         "walls and doors are less reliable (synthetic survey seed 1, the truth's poses: wall "
         "IoU 0.94 at 0.05 m, 0.79 at 0.1 m, 0.33 at 0.025 m; docs/user-guide.md)\n";
}

pipeline::TrackingChoices tracking_choices(const SequenceRunOptions& options) {
  return {options.method,
          options.reestimate_interval,
          {options.anchor_bounds.at(0), options.anchor_bounds.at(1), options.anchor_bounds.at(2)},
          options.tracking,
          options.model_voxel};
}

registration::OdometryParams odometry_params(const SequenceRunOptions& options) {
  return pipeline::odometry_params(tracking_choices(options));
}

mapping::ModelTrackingParams model_tracking_params(const SequenceRunOptions& options) {
  return pipeline::model_tracking_params(tracking_choices(options));
}

std::string model_tracking_line(const mapping::OdometryRun& run) {
  if (!run.model_tracking) return {};
  const double frames = static_cast<double>(std::max<std::size_t>(run.poses.size(), 1));
  char line[160];
  std::snprintf(line, sizeof(line),
                "  model tracking: the model's pose kept on %zu of %zu frames, %.1f ms/frame, "
                "%zu evictions of the blocks least recently seen\n",
                run.model_kept, run.poses.size(), 1000.0 * run.model_seconds / frames,
                run.model_evictions);
  return line;
}

compute::Context make_run_context(const SequenceRunOptions& options) {
  return backend_context(options.backend, options.backend_source);
}

io::SequenceRunRecord run_record(const SequenceRunOptions& options,
                                 const compute::Context& context) {
  return {options.sequence.string(), options.method,
          std::string(compute::to_string(context.backend())), context.device_info().name};
}

void require_colour(const io::OpenedSequence& opened, const std::filesystem::path& folder,
                    const std::string& what) {
  require(opened.has_color, what + " needs colour images, and '" + folder.string() +
                                "' has none (a depth camera alone)");
}

OpenedRun open_run(const SequenceRunOptions& options, std::ostream& err, const std::string& poses) {
  OpenedRun run;
  run.pose_mount = pose_mount(options, poses);
  const bool prior_file = !options.motion_prior.empty() && options.motion_prior != "groundtruth";
  const bool offset_given = options.prior_time_offset != 0 || options.prior_time_offset_auto;
  require(!offset_given || prior_file,
          "--prior-time-offset: no --motion-prior FILE to apply it to");
  run.opened =
      open_input(options.sequence, options.input, err, odometry_params(options).depth_range);
  require(!offset_given || run.opened.detected.has_timestamps,
          "--prior-time-offset: '" + options.sequence.string() +
              "' has no timestamps (its frames are matched to the prior by number)");
  if (options.method == "color") {
    require_colour(run.opened, options.sequence, "--method color (colour-checked ICP)");
  } else if (options.method == "planar") {
    require_colour(run.opened, options.sequence, "--method planar (planes of Lab regions)");
  }
  run.source = std::make_unique<pipeline::SequenceFrameSource>(*run.opened.sequence);
  if (prior_file) {
    const std::string named = "odometry --motion-prior";
    run.prior_poses = read_pose_file(named, options.motion_prior);
    run.prior_time_offset = options.prior_time_offset;
    run.source->set_motion_prior(pose_file_lookup(named, run.prior_poses, options.motion_prior,
                                                  !run.opened.detected.has_timestamps,
                                                  run.pose_mount, run.prior_time_offset));
  } else if (!options.motion_prior.empty()) {
    run.source->set_motion_prior(
        known_pose_lookup("odometry", options.motion_prior, !run.opened.detected.has_timestamps));
  }
  return run;
}

ProgressBar::ProgressBar(std::ostream& err, bool enabled)
    : err_(&err), enabled_(enabled), terminal_(enabled && &err == &std::cerr && isatty(2) == 1) {}

void ProgressBar::update(std::string_view stage, std::size_t done, std::size_t total) {
  if (!enabled_ || total == 0) return;
  if (stage != stage_) {
    finish();
    stage_ = std::string(stage);
    last_step_ = -1;
    stage_start_ = std::chrono::steady_clock::now();
  }
  const double fraction = static_cast<double>(done) / static_cast<double>(total);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - stage_start_).count();
  // The stage started with its first frame: a rate needs some time behind it.
  char rate[48] = "";
  if (seconds > 0.2) {
    std::snprintf(rate, sizeof(rate), " (%.1f frames/s)", static_cast<double>(done - 1) / seconds);
  }
  char line[160];
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::snprintf(line, sizeof(line), "\r%-8s [%-*s] %zu/%zu%s", stage_.c_str(), kWidth,
                  std::string(static_cast<std::size_t>(filled), '#').c_str(), done, total, rate);
    *err_ << line << std::flush;
    open_line_ = true;
    return;
  }
  const int step = static_cast<int>(fraction * 10);
  if (step == last_step_) return;
  last_step_ = step;
  std::snprintf(line, sizeof(line), "%s: %zu/%zu frames%s\n", stage_.c_str(), done, total, rate);
  *err_ << line << std::flush;
}

void ProgressBar::finish() {
  if (open_line_) *err_ << "\n" << std::flush;
  open_line_ = false;
}

void warn_about(std::ostream& err, ProgressBar& bar, const registration::OdometryFrame& frame) {
  const auto describe = [](const registration::RegistrationReport& r) {
    char text[160];
    std::snprintf(text, sizeof(text), "%s (fitness %.2f, rmse %.1f mm, eigenvalue ratio %.3f)",
                  std::string(registration::to_string(r.verdict)).c_str(), r.fitness,
                  1000.0 * r.inlier_rmse, r.eigenvalue_ratio);
    return std::string(text);
  };
  if (frame.fallback && frame.previous) {
    bar.finish();
    err << "warning: frame " << frame.index
        << ": registration to the previous frame rejected: " << describe(*frame.previous)
        << "; using the constant-velocity motion\n";
  }
  if (frame.reestimate && !frame.reestimate->accepted()) {
    bar.finish();
    err << "warning: frame " << frame.index
        << ": re-estimate rejected: " << describe(*frame.reestimate)
        << "; keeping the chained estimate\n";
  }
}

mapping::SlamObserver slam_progress_observer(std::ostream& err, ProgressBar& bar) {
  mapping::SlamObserver observer;
  observer.on_frame = [&err, &bar](const registration::OdometryFrame& f) {
    warn_about(err, bar, f);
  };
  observer.on_progress = [&bar](std::string_view stage, std::size_t done, std::size_t total) {
    bar.update(stage, done, total);
  };
  return observer;
}

Trajectory stamped_trajectory(const std::vector<Eigen::Isometry3d>& poses,
                              const std::vector<double>& timestamps, bool has_timestamps) {
  Trajectory trajectory;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    trajectory.push_back({has_timestamps ? timestamps.at(i) : static_cast<double>(i), poses[i]});
  }
  return trajectory;
}

Trajectory ground_truth_trajectory(const pipeline::SequenceFrameSource& source,
                                   const std::vector<double>& timestamps, bool has_timestamps) {
  Trajectory trajectory;
  const auto& truth = source.ground_truth();
  for (std::size_t i = 0; i < truth.size() && i < timestamps.size(); ++i) {
    if (truth[i]) {
      trajectory.push_back({has_timestamps ? timestamps[i] : static_cast<double>(i), *truth[i]});
    }
  }
  return trajectory;
}

std::optional<eval::AteResult> absolute_trajectory_error(
    const pipeline::SequenceFrameSource& source, const std::vector<Eigen::Isometry3d>& poses) {
  const eval::MatchedPoses matched = eval::match_frames(source.ground_truth(), poses);
  if (matched.size() < 3) return std::nullopt;
  return eval::compute_ate(matched, eval::Alignment::se3);
}

std::optional<eval::MeasuredPoseAte> ate_at_measured_poses(
    const pipeline::SequenceFrameSource& source, const std::vector<Eigen::Isometry3d>& poses) {
  const eval::MatchedPoses matched = eval::match_frames(source.ground_truth(), poses);
  if (matched.size() < 3) return std::nullopt;
  return eval::ate_at_measured_poses(matched);
}

std::string measured_poses_line(const eval::MeasuredPoseAte& measured) {
  char line[160];
  std::snprintf(line, sizeof(line),
                "  ground truth measured every %zu frames, interpolated between: ate_rmse_m %.6f "
                "at its %zu measured poses\n",
                measured.period, measured.ate.translation_m.rmse, measured.ate.translation_m.count);
  return line;
}

void add_pose_mount_option(CLI::App& command, std::vector<double>& mount) {
  command
      .add_option("--pose-mount", mount,
                  "x,y,z,qx,qy,qz,qw: the camera's pose in the body whose poses a --poses or "
                  "--motion-prior FILE gives (e.g. a robot base's odometry: base to camera "
                  "optical frame); default: the file gives the camera's own poses")
      ->expected(7)
      ->delimiter(',')
      ->check(finite_number());
}

Eigen::Isometry3d pose_mount(const SequenceRunOptions& options, const std::string& poses) {
  const std::vector<double>& m = options.pose_mount;
  if (m.empty()) return Eigen::Isometry3d::Identity();
  const bool file_given = (!poses.empty() && poses != "groundtruth") ||
                          (!options.motion_prior.empty() && options.motion_prior != "groundtruth");
  require(file_given,
          "--pose-mount: no --poses or --motion-prior FILE to apply it to (a sequence's own "
          "ground truth is the camera's)");
  const Eigen::Quaterniond rotation(m[6], m[3], m[4], m[5]);
  require(std::fabs(rotation.norm() - 1) <= 1e-3,
          "--pose-mount: quaternion (" + std::to_string(m[3]) + ", " + std::to_string(m[4]) + ", " +
              std::to_string(m[5]) + ", " + std::to_string(m[6]) + ") has norm " +
              std::to_string(rotation.norm()) + ", not 1");
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = rotation.normalized().toRotationMatrix();
  mount.translation() = Eigen::Vector3d(m[0], m[1], m[2]);
  return mount;
}

// --poses: each frame's pose from the sequence's ground truth or from a TUM file at the frame's
// timestamp (interpolated between the file's poses: pose_at), or at its frame number where the
// layout has no timestamps (as the trajectories Kartograf writes for it are stamped); a frame
// without one stops the run with an Error naming it.
mapping::KnownPoseLookup known_pose_lookup(const std::string& command, const std::string& poses,
                                           bool by_frame_number, const std::string& option,
                                           const Eigen::Isometry3d& mount, double time_offset) {
  if (poses.empty()) return {};
  const std::string named = command + " " + option;
  if (poses == "groundtruth") {
    return [named](std::size_t i, const registration::RgbdImages& images) {
      require(images.ground_truth.has_value(), named + " groundtruth: frame " + std::to_string(i) +
                                                   " has no ground-truth pose in the sequence");
      return *images.ground_truth;
    };
  }
  return pose_file_lookup(named, read_pose_file(named, poses), poses, by_frame_number, mount,
                          time_offset);
}

std::shared_ptr<const Trajectory> read_pose_file(const std::string& named,
                                                 const std::string& file) {
  auto trajectory = std::make_shared<Trajectory>(io::read_tum_trajectory(file));
  require(!trajectory->empty(), named + ": '" + file + "' holds no pose");
  sort_by_time(*trajectory);
  return trajectory;
}

mapping::KnownPoseLookup pose_file_lookup(const std::string& named,
                                          std::shared_ptr<const Trajectory> trajectory,
                                          const std::string& poses, bool by_frame_number,
                                          const Eigen::Isometry3d& mount, double time_offset) {
  return [named, trajectory, poses, by_frame_number, mount, time_offset](
             std::size_t i, const registration::RgbdImages& images) {
    const double stamp = by_frame_number ? static_cast<double>(i) : images.timestamp + time_offset;
    const std::optional<Eigen::Isometry3d> pose = pose_at(*trajectory, stamp);
    require(pose.has_value(),
            named + ": '" + poses + "' has no pose within 20 ms of frame " + std::to_string(i) +
                " (" + (by_frame_number ? "frame number " : "timestamp ") + std::to_string(stamp) +
                "), nor two at most 0.5 s apart around it");
    return Eigen::Isometry3d(*pose * mount);
  };
}

std::optional<io::PriorClock> measure_prior_clock(const OpenedRun& run,
                                                  const std::vector<Eigen::Isometry3d>& poses,
                                                  const std::vector<double>& timestamps) {
  if (!run.prior_poses || !run.opened.detected.has_timestamps || poses.size() < 2)
    return std::nullopt;
  eval::ClockOffsetSearch search;
  search.given_s = run.prior_time_offset;
  return io::PriorClock{run.prior_time_offset,
                        eval::estimate_clock_offset(stamped_trajectory(poses, timestamps, true),
                                                    *run.prior_poses, search)};
}

void calibrate_prior_clock(const SequenceRunOptions& options, const compute::Context& context,
                           OpenedRun& run, std::ostream& err) {
  if (!options.prior_time_offset_auto) return;
  // The first 20 s at 30 Hz without the prior: the camera's own steps, whatever the file's clock.
  constexpr std::size_t kFrames = 600;
  const pipeline::SequenceFrameSource first(*run.opened.sequence,
                                            std::min(kFrames, run.source->size()));
  err << "motion prior clock: tracking the first " << first.size()
      << " frames without the prior to measure it (--prior-time-offset auto)\n";
  const mapping::OdometryRun odometry = mapping::run_odometry(
      context, first, odometry_params(options), {}, model_tracking_params(options));
  const std::optional<io::PriorClock> clock =
      measure_prior_clock(run, odometry.poses, odometry.timestamps);
  require(clock && clock->measured.observable,
          "--prior-time-offset auto: the motion prior's clock is not measurable from the first " +
              std::to_string(first.size()) + " frames (" +
              (clock ? io::prior_clock_text(*clock) : std::string("fewer than two")) +
              "): give --prior-time-offset S");
  run.prior_time_offset = clock->measured.offset_s;
  run.source->set_motion_prior(pose_file_lookup("odometry --motion-prior", run.prior_poses,
                                                options.motion_prior, false, run.pose_mount,
                                                run.prior_time_offset));
  char line[160];
  std::snprintf(line, sizeof(line),
                "motion prior clock: %+.3f s (+- %.1f ms) measured over the first %zu frames "
                "(--prior-time-offset auto)\n",
                run.prior_time_offset, 1000 * clock->measured.sigma_s, first.size());
  err << line;
}

std::string prior_clock_line(const std::optional<io::PriorClock>& clock) {
  return clock ? "  motion prior clock: " + io::prior_clock_text(*clock) + "\n" : "";
}

}  // namespace kartograf::cli
