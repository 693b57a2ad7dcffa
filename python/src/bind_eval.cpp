#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/core/error.hpp"
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

// Frame k of the estimate against frame k of the ground truth (None: no ground truth there).
nb::dict ate(const PoseStack& estimate, const nb::list& ground_truth, const std::string& align) {
  require(align == "se3" || align == "sim3" || align == "none",
          "ate: align must be 'se3', 'sim3' or 'none', not '" + align + "'");
  std::vector<std::optional<Eigen::Isometry3d>> truth;
  for (const nb::handle item : ground_truth) {
    if (item.is_none()) {
      truth.emplace_back();
    } else {
      truth.emplace_back(to_pose(nb::cast<PoseArray>(item), "ate: ground truth"));
    }
  }
  const std::vector<Eigen::Isometry3d> poses = poses_of(estimate, "ate: estimate");
  const eval::MatchedPoses matched = eval::match_frames(truth, poses);
  require(matched.size() >= 3, "ate: fewer than 3 frames have both a pose and ground truth");
  const eval::AteResult result =
      eval::compute_ate(matched, align == "se3"    ? eval::Alignment::se3
                                 : align == "sim3" ? eval::Alignment::sim3
                                                   : eval::Alignment::none);
  nb::dict d;
  d["rmse_m"] = result.translation_m.rmse;
  d["mean_m"] = result.translation_m.mean;
  d["median_m"] = result.translation_m.median;
  d["max_m"] = result.translation_m.max;
  d["count"] = result.translation_m.count;
  d["scale"] = result.alignment.scale;
  return d;
}

}  // namespace

void bind_eval(nb::module_& m) {
  m.def("ate", &ate, nb::arg("estimate"), nb::arg("ground_truth"), nb::arg("align") = "se3",
        "Absolute trajectory error: estimate N x 4 x 4 against a list of 4 x 4 or None");
}

}  // namespace kartograf::python
