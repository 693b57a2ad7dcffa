#include "reports.hpp"

#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>

#include "convert.hpp"

namespace kartograf::python {

nb::dict registration_dict(const registration::RegistrationReport& report) {
  nb::dict d;
  d["verdict"] = std::string(registration::to_string(report.verdict));
  d["accepted"] = report.accepted();
  d["fitness"] = report.fitness;
  d["inlier_rmse"] = report.inlier_rmse;
  d["inliers"] = report.inliers;
  d["iterations"] = report.iterations;
  d["converged"] = report.converged;
  d["degenerate"] = report.degenerate;
  d["correction_m"] = report.correction_m;
  d["correction_deg"] = report.correction_deg;
  return d;
}

nb::dict frame_dict(const registration::OdometryFrame& frame) {
  nb::dict d;
  d["index"] = frame.index;
  d["previous"] = frame.previous ? nb::object(registration_dict(*frame.previous)) : nb::none();
  d["reestimate"] =
      frame.reestimate ? nb::object(registration_dict(*frame.reestimate)) : nb::none();
  d["retried"] = frame.retried;
  d["from_features"] = frame.from_features;
  d["from_motion_prior"] = frame.from_motion_prior;
  d["prior_difference_m"] = frame.prior_difference_m;
  d["prior_difference_deg"] = frame.prior_difference_deg;
  d["fallback"] = frame.fallback;
  d["degenerate"] = frame.degenerate;
  d["degenerate_overlap"] = frame.degenerate_overlap;
  d["reestimate_degenerate_overlap"] = frame.reestimate_degenerate_overlap;
  d["photometric"] = frame.photometric;
  d["heading_sigma_m"] = frame.heading_sigma_m;
  d["accelerated"] = frame.accelerated;
  d["speed_bounded"] = frame.speed_bounded;
  d["scanned"] = frame.scanned;
  d["eigenvalue_ratio"] = frame.eigenvalue_ratio;
  d["keyframe"] = frame.keyframe;
  d["seconds"] = frame.seconds;
  return d;
}

nb::dict odometry_run_dict(const mapping::OdometryRun& run) {
  nb::dict d;
  d["poses"] = pose_stack(run.poses);
  d["timestamps"] = run.timestamps;
  nb::list frames;
  for (const registration::OdometryFrame& f : run.frames) frames.append(frame_dict(f));
  d["frames"] = frames;
  d["keyframes"] = run.keyframes;
  d["wall_seconds"] = run.timing.wall_seconds;
  d["load_seconds"] = run.timing.load_seconds;
  d["compute_seconds"] = run.compute_seconds;
  d["model_tracking"] = run.model_tracking;
  d["model_kept"] = run.model_kept;
  return d;
}

}  // namespace kartograf::python
