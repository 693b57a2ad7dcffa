#include "kartograf/outputs/odometry_stats.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <utility>
#include <vector>

#include "run_json.hpp"

namespace kartograf::io {

namespace detail {

RunJson input_json(const OpenedSequence& opened) {
  const PinholeIntrinsics& k = opened.camera.intrinsics;
  RunJson skipped = RunJson::array();
  for (const SkippedFrame& frame : opened.skipped)
    skipped.push_back({{"frame", frame.position}, {"reason", frame.reason}});
  return {{"camera",
           {{"fx", k.fx},
            {"fy", k.fy},
            {"cx", k.cx},
            {"cy", k.cy},
            {"width", k.width},
            {"height", k.height},
            {"source", opened.camera.source},
            {"description", opened.camera.description}}},
          {"colour", opened.has_color},  // false: a depth camera alone
          {"depth_units_per_metre", opened.sequence->depth_units_per_metre()},
          {"depth_scale_source", opened.depth_scale_source},
          {"frames_skipped", opened.skipped.size()},
          {"skipped_frames", std::move(skipped)}};
}

RunJson registration_report_json(const registration::RegistrationReport& r) {
  RunJson json;
  json["verdict"] = registration::to_string(r.verdict);
  json["fitness"] = r.fitness;
  json["inlier_rmse_m"] = r.inlier_rmse;
  json["inliers"] = r.inliers;
  json["iterations"] = r.iterations;
  json["converged"] = r.converged;
  json["degenerate"] = r.degenerate;
  json["eigenvalue_ratio"] = r.eigenvalue_ratio;
  json["correction_m"] = r.correction_m;
  json["correction_deg"] = r.correction_deg;
  return json;
}

namespace {

RunJson frame_json(const registration::OdometryFrame& frame) {
  RunJson json;
  json["frame"] = frame.index;
  json["keyframe"] = frame.keyframe;
  json["fallback"] = frame.fallback;
  json["retried"] = frame.retried;
  json["from_features"] = frame.from_features;
  json["from_motion_prior"] = frame.from_motion_prior;
  if (frame.from_motion_prior) {
    json["prior_difference_m"] = frame.prior_difference_m;
    json["prior_difference_deg"] = frame.prior_difference_deg;
  }
  json["degenerate"] = frame.degenerate;
  json["degenerate_overlap"] = frame.degenerate_overlap;
  json["reestimate_degenerate_overlap"] = frame.reestimate_degenerate_overlap;
  json["photometric"] = frame.photometric;
  json["deep_photometric"] = frame.deep_photometric;
  json["heading_sigma_m"] = frame.heading_sigma_m;
  json["accelerated"] = frame.accelerated;
  json["speed_bounded"] = frame.speed_bounded;
  json["scanned"] = frame.scanned;
  json["eigenvalue_ratio"] = frame.eigenvalue_ratio;
  json["step_frame"] = std::string(registration::to_string(frame.step_frame));
  json["previous"] = frame.previous ? registration_report_json(*frame.previous) : RunJson();
  json["reestimate"] = frame.reestimate ? registration_report_json(*frame.reestimate) : RunJson();
  if (frame.reestimate) json["reestimate_anchor"] = frame.reestimate_anchor;
  json["seconds"] = frame.seconds;
  return json;
}

}  // namespace

RunJson frame_counts_json(const std::vector<registration::OdometryFrame>& frames) {
  const OdometryFrameCounts counts = count_odometry_frames(frames);
  RunJson json;
  json["frames"] = counts.frames;
  json["keyframes"] = counts.keyframes;
  json["fallbacks"] = counts.fallbacks;
  json["retried_from_other_starts"] = counts.retried_from_other_starts;
  json["from_features"] = counts.from_features;
  json["motion_prior_frames"] = counts.motion_prior_frames;
  json["motion_prior_difference_median_m"] = counts.prior_difference.median_m;
  json["motion_prior_difference_max_m"] = counts.prior_difference.max_m;
  json["motion_prior_difference_max_deg"] = counts.prior_difference.max_deg;
  json["degenerate_frames"] = counts.degenerate_frames;
  json["degenerate_overlap_frames"] = counts.degenerate_overlap_frames;
  json["photometric_frames"] = counts.photometric_frames;
  json["deep_photometric_frames"] = counts.deep_photometric_frames;
  json["colour_registration"] = std::string(registration::to_string(counts.colour_registration));
  json["colour_edge_contrast"] = counts.colour_edge_contrast;
  json["heading_prior_frames"] = counts.heading_prior_frames;
  json["accelerated_frames"] = counts.accelerated_frames;
  json["speed_bounded_frames"] = counts.speed_bounded_frames;
  json["scanned_frames"] = counts.scanned_frames;
  json["reestimates"] = counts.reestimates;
  json["reestimates_rejected"] = counts.reestimates_rejected;
  json["reestimates_on_degenerate_overlap"] = counts.reestimates_on_degenerate_overlap;
  return json;
}

RunJson per_frame_json(const std::vector<registration::OdometryFrame>& frames) {
  RunJson json = RunJson::array();
  for (const registration::OdometryFrame& frame : frames) json.push_back(frame_json(frame));
  return json;
}

}  // namespace detail

std::string sequence_input_json(const OpenedSequence& opened) {
  return detail::input_json(opened).dump();
}

namespace {

MotionPriorDifference motion_prior_difference(
    const std::vector<registration::OdometryFrame>& frames) {
  MotionPriorDifference d;
  std::vector<double> metres;
  for (const registration::OdometryFrame& f : frames) {
    if (!f.from_motion_prior) continue;
    metres.push_back(f.prior_difference_m);
    d.max_m = std::max(d.max_m, f.prior_difference_m);
    d.max_deg = std::max(d.max_deg, f.prior_difference_deg);
  }
  if (metres.empty()) return d;
  const auto middle = metres.begin() + static_cast<std::ptrdiff_t>(metres.size() / 2);
  std::nth_element(metres.begin(), middle, metres.end());
  d.median_m = *middle;
  return d;
}

}  // namespace

OdometryFrameCounts count_odometry_frames(const std::vector<registration::OdometryFrame>& frames) {
  OdometryFrameCounts counts;
  counts.prior_difference = motion_prior_difference(frames);
  counts.frames = frames.size();
  for (const registration::OdometryFrame& f : frames) {
    counts.fallbacks += f.fallback;
    counts.retried_from_other_starts += f.retried;
    counts.from_features += f.from_features;
    counts.motion_prior_frames += f.from_motion_prior;
    counts.keyframes += f.keyframe;
    counts.degenerate_frames += f.degenerate;
    counts.degenerate_overlap_frames += f.degenerate_overlap;
    counts.photometric_frames += f.photometric;
    counts.heading_prior_frames += f.heading_sigma_m > 0;
    counts.accelerated_frames += f.accelerated;
    counts.speed_bounded_frames += f.speed_bounded;
    counts.scanned_frames += f.scanned;
    counts.reestimates += f.reestimate.has_value();
    counts.reestimates_rejected += f.reestimate && !f.reestimate->accepted();
    counts.reestimates_on_degenerate_overlap += f.reestimate_degenerate_overlap;
    counts.deep_photometric_frames += f.deep_photometric;
  }
  if (!frames.empty()) {
    counts.colour_registration = frames.back().colour_registration;
    counts.colour_edge_contrast = frames.back().colour_edge_contrast;
  }
  return counts;
}

namespace {

// Sparse sequences only (OdometryParams::overlap_turn_deg, acceleration_start, step_scan,
// speed_change_margin).
std::string speed_changes_text(const OdometryFrameCounts& c) {
  std::string text;
  if (c.degenerate_overlap_frames > 0) {
    text += ", " + std::to_string(c.degenerate_overlap_frames) + " only where a turn overlapped";
  }
  if (c.accelerated_frames > 0) {
    text += ", " + std::to_string(c.accelerated_frames) + " followed a change of speed";
  }
  if (c.scanned_frames > 0) {
    text += ", " + std::to_string(c.scanned_frames) + " found along the step";
  }
  if (c.speed_bounded_frames > 0) {
    text += ", " + std::to_string(c.speed_bounded_frames) + " decided by the speed bound";
  }
  return text;
}

// Runs with colour: whether it is registered to the depth, and the deep views the images measured
// (OdometryParams::photometric_deep_weight).
std::string colour_text(const OdometryFrameCounts& c) {
  if (c.colour_edge_contrast <= 0) return "";
  char contrast[32];
  std::snprintf(contrast, sizeof(contrast), "%.2f", c.colour_edge_contrast);
  return "; colour " + std::string(registration::to_string(c.colour_registration)) +
         " to depth (edge contrast " + contrast + "), deep views measured with the images " +
         std::to_string(c.deep_photometric_frames);
}

std::string reestimates_on_overlap_text(const OdometryFrameCounts& c) {
  if (c.reestimates_on_degenerate_overlap == 0) return "";
  return ", " + std::to_string(c.reestimates_on_degenerate_overlap) +
         " held where the anchor saw a degenerate view";
}

}  // namespace

std::string frame_counts_line(const OdometryFrameCounts& c) {
  const auto count = [](std::size_t n) { return std::to_string(n); };
  std::string seeded = c.from_features ? ", started from features " + count(c.from_features) : "";
  if (c.motion_prior_frames > 0) {
    char off[96];
    std::snprintf(off, sizeof(off),
                  " (its steps off by median %.1f mm, at most %.1f mm and %.2f deg)",
                  1000 * c.prior_difference.median_m, 1000 * c.prior_difference.max_m,
                  c.prior_difference.max_deg);
    seeded += ", predicted by the motion prior " + count(c.motion_prior_frames) + off;
  }
  return "keyframes " + count(c.keyframes) + ", fallbacks " + count(c.fallbacks) + seeded +
         ", re-estimates " + count(c.reestimates) + " (rejected " + count(c.reestimates_rejected) +
         reestimates_on_overlap_text(c) + "), degenerate frames " + count(c.degenerate_frames) +
         " (" + count(c.photometric_frames) + " measured by image intensity, " +
         count(c.heading_prior_frames) + " held to the heading" + speed_changes_text(c) + ")" +
         colour_text(c);
}

OdometryThroughput odometry_throughput(const mapping::OdometryRun& run) {
  const double frames = static_cast<double>(run.poses.size());
  OdometryThroughput throughput;
  throughput.with_io = run.timing.wall_seconds > 0 ? frames / run.timing.wall_seconds : 0;
  throughput.without_io = run.compute_seconds > 0 ? frames / run.compute_seconds : 0;
  return throughput;
}

std::string odometry_stats_json(const SequenceRunRecord& record, const OpenedSequence& opened,
                                const registration::OdometryParams& params,
                                const mapping::OdometryRun& run,
                                const std::optional<eval::AteResult>& ate) {
  using detail::RunJson;
  const OdometryThroughput throughput = odometry_throughput(run);
  RunJson json;
  json["sequence"] = record.sequence;
  json["layout"] = to_string(opened.detected.layout);
  json["input"] = detail::input_json(opened);
  json["method"] = record.method;
  json["backend"] = record.backend;
  json["device"] = record.device;
  json["reestimate_interval"] = params.reestimate_interval;
  json["frames_per_s_with_io"] = throughput.with_io;
  json["frames_per_s_without_io"] = throughput.without_io;
  json["wall_seconds"] = run.timing.wall_seconds;
  json["load_seconds"] = run.timing.load_seconds;
  json["ate_rmse_m"] = ate ? RunJson(ate->translation_m.rmse) : RunJson();
  json["summary"] = detail::frame_counts_json(run.frames);
  json["per_frame"] = detail::per_frame_json(run.frames);
  return json.dump(1) + "\n";
}

}  // namespace kartograf::io
