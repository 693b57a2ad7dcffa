#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/eval/clock_offset.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"

namespace kartograf::python {

namespace {

using PoseStack = nb::ndarray<const double, nb::shape<-1, 4, 4>, nb::device::cpu>;

std::vector<Eigen::Isometry3d> poses_of(const PoseStack& stack, const char* what) {
  std::vector<Eigen::Isometry3d> poses;
  const auto view = stack.view();
  for (std::size_t i = 0; i < stack.shape(0); ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = view(i, r, c);
    require(pose.matrix().allFinite(),
            std::string(what) + ": pose " + std::to_string(i) + " is not finite");
    poses.push_back(pose);
  }
  return poses;
}

eval::Alignment alignment_of(const std::string& align, const std::string& what) {
  require(align == "se3" || align == "sim3" || align == "none",
          what + ": align must be 'se3', 'sim3' or 'none', not '" + align + "'");
  return align == "se3"    ? eval::Alignment::se3
         : align == "sim3" ? eval::Alignment::sim3
                           : eval::Alignment::none;
}

// Frame k of the estimate against frame k of the ground truth (None: no ground truth there).
eval::MatchedPoses matched_frames(const PoseStack& estimate, const nb::list& ground_truth,
                                  const std::string& what) {
  std::vector<std::optional<Eigen::Isometry3d>> truth;
  for (const nb::handle item : ground_truth) {
    if (item.is_none()) {
      truth.emplace_back();
    } else {
      truth.emplace_back(to_pose(nb::cast<PoseArray>(item), (what + ": ground truth").c_str()));
    }
  }
  const std::vector<Eigen::Isometry3d> poses = poses_of(estimate, (what + ": estimate").c_str());
  eval::MatchedPoses matched = eval::match_frames(truth, poses);
  require(matched.size() >= 3, what + ": fewer than 3 frames have both a pose and ground truth");
  return matched;
}

nb::dict ate(const PoseStack& estimate, const nb::list& ground_truth, const std::string& align) {
  const eval::Alignment alignment = alignment_of(align, "ate");
  const eval::AteResult result =
      eval::compute_ate(matched_frames(estimate, ground_truth, "ate"), alignment);
  nb::dict d;
  d["rmse_m"] = result.translation_m.rmse;
  d["mean_m"] = result.translation_m.mean;
  d["median_m"] = result.translation_m.median;
  d["max_m"] = result.translation_m.max;
  d["count"] = result.translation_m.count;
  d["scale"] = result.alignment.scale;
  return d;
}

// eval::worst_steps; a step's "frame" is the frame it ends at (steps join frames with ground
// truth).
nb::dict worst_steps(const PoseStack& estimate, const nb::list& ground_truth, std::size_t count,
                     const std::string& align) {
  const eval::Alignment alignment = alignment_of(align, "worst_steps");
  const eval::MatchedPoses matched = matched_frames(estimate, ground_truth, "worst_steps");
  const eval::WorstSteps worst = eval::worst_steps(matched, count, alignment);
  nb::list steps;
  for (const eval::StepError& step : worst.steps) {
    nb::dict d;
    d["frame"] = static_cast<std::size_t>(matched.estimate[step.pose].timestamp);
    d["translation_m"] = step.translation_m;
    d["rotation_deg"] = step.rotation_deg;
    d["ate_rmse_with_true_step_m"] = step.ate_rmse_with_true_step_m;
    steps.append(d);
  }
  nb::dict d;
  d["steps"] = steps;
  d["ate_rmse_m"] = worst.ate_rmse_m;
  d["ate_rmse_with_true_steps_m"] = worst.ate_rmse_with_true_steps_m;
  return d;
}

using Times = nb::ndarray<const double, nb::shape<-1>, nb::device::cpu>;

// Times and poses of one trajectory, sorted by time; an Error naming `what` where their counts
// differ or a time is not finite.
Trajectory trajectory_of(const Times& times, const PoseStack& poses, const std::string& what) {
  require(times.shape(0) == poses.shape(0), what + ": " + std::to_string(times.shape(0)) +
                                                " times but " + std::to_string(poses.shape(0)) +
                                                " poses");
  const std::vector<Eigen::Isometry3d> matrices = poses_of(poses, what.c_str());
  Trajectory trajectory;
  const auto view = times.view();
  for (std::size_t i = 0; i < matrices.size(); ++i) {
    require(std::isfinite(view(i)), what + ": time " + std::to_string(i) + " is not finite");
    trajectory.push_back({view(i), matrices[i]});
  }
  sort_by_time(trajectory);
  return trajectory;
}

nb::dict clock_offset(const Times& times, const PoseStack& poses, const Times& other_times,
                      const PoseStack& other_poses, double given, double half_range) {
  eval::ClockOffsetSearch search;
  search.given_s = given;
  search.half_range_s = half_range;
  const eval::ClockOffsetEstimate e = eval::estimate_clock_offset(
      trajectory_of(times, poses, "clock_offset: trajectory"),
      trajectory_of(other_times, other_poses, "clock_offset: other"), search);
  nb::dict d;
  d["offset_s"] = e.offset_s;
  d["sigma_s"] = e.sigma_s;
  d["rms_deg"] = e.rms_deg;
  d["given_rms_deg"] = e.given_rms_deg;
  d["steps"] = e.steps;
  d["observable"] = e.observable;
  return d;
}

}  // namespace

void bind_eval(nb::module_& m) {
  m.def("ate", &ate, nb::arg("estimate"), nb::arg("ground_truth"), nb::arg("align") = "se3",
        "Absolute trajectory error: estimate N x 4 x 4 against a list of 4 x 4 or None");
  m.def("worst_steps", &worst_steps, nb::arg("estimate"), nb::arg("ground_truth"),
        nb::arg("count") = 10, nb::arg("align") = "se3",
        "The steps with the largest error, each with the ATE with that step from the ground "
        "truth (kartograf eval traj --worst-steps)");
  m.def("clock_offset", &clock_offset, nb::arg("times"), nb::arg("poses"), nb::arg("other_times"),
        nb::arg("other_poses"), nb::arg("given") = 0.0, nb::arg("half_range") = 0.5,
        "The other trajectory's clock lead from how fast both turn (eval::estimate_clock_offset)");
}

}  // namespace kartograf::python
