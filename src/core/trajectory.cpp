#include "kartograf/core/trajectory.hpp"

#include <algorithm>
#include <cmath>

namespace kartograf {
namespace {

Eigen::Isometry3d interpolated(const StampedPose& a, const StampedPose& b, double t) {
  const double span = b.timestamp - a.timestamp;
  const double f = span > 0 ? (t - a.timestamp) / span : 0.0;
  const Eigen::Quaterniond qa(a.pose.linear());
  const Eigen::Quaterniond qb(b.pose.linear());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = qa.slerp(f, qb).toRotationMatrix();  // Eigen's slerp takes the shorter arc
  pose.translation() = (1 - f) * a.pose.translation() + f * b.pose.translation();
  return pose;
}

}  // namespace

void sort_by_time(Trajectory& trajectory) {
  std::stable_sort(
      trajectory.begin(), trajectory.end(),
      [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
}

std::optional<Eigen::Isometry3d> pose_at(const Trajectory& by_time, double t,
                                         const PoseAtTolerance& tolerance) {
  const auto after =
      std::lower_bound(by_time.begin(), by_time.end(), t,
                       [](const StampedPose& p, double s) { return p.timestamp < s; });
  const bool has_after = after != by_time.end();
  const bool has_before = after != by_time.begin();
  if (has_after && has_before) {
    const StampedPose& before = *std::prev(after);
    if (after->timestamp - before.timestamp <= tolerance.max_gap)
      return interpolated(before, *after, t);
  }
  const StampedPose* nearest = nullptr;
  if (has_after) nearest = &*after;
  if (has_before && (!nearest || t - std::prev(after)->timestamp < nearest->timestamp - t))
    nearest = &*std::prev(after);
  if (nearest && std::fabs(nearest->timestamp - t) <= tolerance.max_offset) return nearest->pose;
  return std::nullopt;
}

}  // namespace kartograf
