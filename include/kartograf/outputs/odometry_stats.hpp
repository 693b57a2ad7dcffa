#pragma once
// The documents of a run over an RGB-D sequence (`kartograf odometry`, `slam`, `map`, `planes`):
// the input as read, counts over the odometry's frames, and odometry's stats.json (per-frame
// registration reports). JSON text, written as it is by the caller.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::io {

// How a run was asked for, as its stats record it.
struct SequenceRunRecord {
  std::string sequence;  // the folder as given
  std::string method;    // the odometry's name: p2p, p2plane, color, planar
  std::string backend;   // compute::to_string of the context's backend
  std::string device;
};

// The camera, depth scale and frames left out, a JSON object (the "input" of stats and reports).
std::string sequence_input_json(const OpenedSequence& opened);

// How far the steps a motion prior predicted were from those the odometry took (the frames
// from_motion_prior): the median and largest translation, the largest rotation; 0 without any.
struct MotionPriorDifference {
  double median_m = 0, max_m = 0, max_deg = 0;
};

// Counts over an odometry run's frames.
struct OdometryFrameCounts {
  std::size_t frames = 0, keyframes = 0, fallbacks = 0, retried_from_other_starts = 0,
              from_features = 0, degenerate_frames = 0, photometric_frames = 0, reestimates = 0,
              reestimates_rejected = 0, heading_prior_frames = 0, accelerated_frames = 0,
              speed_bounded_frames = 0, scanned_frames = 0, degenerate_overlap_frames = 0,
              reestimates_on_degenerate_overlap = 0, motion_prior_frames = 0,
              deep_photometric_frames = 0;
  MotionPriorDifference prior_difference;
  // The odometry's verdict on the colour's registration to the depth, as at the last frame, and
  // the edge contrast it judged (0: no colour).
  registration::ColourRegistration colour_registration =
      registration::ColourRegistration::undecided;
  double colour_edge_contrast = 0;
};
OdometryFrameCounts count_odometry_frames(const std::vector<registration::OdometryFrame>& frames);
// Those counts in one line, for the summaries on stdout.
std::string frame_counts_line(const OdometryFrameCounts& counts);

// Frames per second of an odometry run with file I/O (wall time) and without (compute time);
// 0 where a time is 0.
struct OdometryThroughput {
  double with_io = 0, without_io = 0;
};
OdometryThroughput odometry_throughput(const mapping::OdometryRun& run);

// `kartograf odometry --stats`: the run, its throughput and ATE (null without ground truth), the
// frame counts and every frame's registration reports; ends with a newline.
std::string odometry_stats_json(const SequenceRunRecord& record, const OpenedSequence& opened,
                                const registration::OdometryParams& params,
                                const mapping::OdometryRun& run,
                                const std::optional<eval::AteResult>& ate);

}  // namespace kartograf::io
