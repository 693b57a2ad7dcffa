#include "kartograf/semantic/labelled_views.hpp"

#include <algorithm>
#include <cmath>

#include "kartograf/core/error.hpp"

namespace kartograf::semantic {

void LabelledViews::add(const PointImage& points, const SemanticImage& labels,
                        const GravityEstimate& gravity, const Eigen::Isometry3d& sensor_to_world) {
  require(points.width() == labels.width() && points.height() == labels.height(),
          "LabelledViews: " + std::to_string(points.width()) + "x" +
              std::to_string(points.height()) + " points but " + std::to_string(labels.width()) +
              "x" + std::to_string(labels.height()) + " labels");
  up_sum_ += gravity.support_area * (sensor_to_world.linear() * gravity.up);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point4f& p = points.data()[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) continue;
    points_.push_back(sensor_to_world * p.head<3>().cast<double>());
    labels_.push_back(labels.data()[i]);
    view_ids_.push_back(static_cast<std::uint32_t>(views_));
  }
  origins_.push_back(sensor_to_world.translation());
  ++views_;
}

void LabelledViews::skip(const std::string& reason) {
  if (skipped_++ == 0) first_skip_reason_ = reason;
}

Eigen::Vector3d LabelledViews::up() const {
  return up_sum_.norm() > 0 ? Eigen::Vector3d(up_sum_.normalized()) : Eigen::Vector3d::UnitZ();
}

Eigen::Matrix3d LabelledViews::make_up_z() {
  const Eigen::Matrix3d rotation =
      Eigen::Quaterniond::FromTwoVectors(up(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  transform(Eigen::Isometry3d(rotation));
  return rotation;
}

void LabelledViews::transform(const Eigen::Isometry3d& transform) {
  for (Eigen::Vector3d& p : points_) p = transform * p;
  for (Eigen::Vector3d& o : origins_) o = transform * o;
}

namespace {

// The median of the sorted heights in [lo, hi] (none when none lie there).
std::optional<double> median_between(const std::vector<double>& sorted, double lo, double hi) {
  const auto first = std::lower_bound(sorted.begin(), sorted.end(), lo);
  const auto last = std::upper_bound(first, sorted.end(), hi);
  if (first == last) return std::nullopt;
  return *(first + (last - first) / 2);
}

}  // namespace

std::optional<double> floor_level(std::vector<double> heights) {
  constexpr double kBin = 0.05;       // m: levels are told apart at 2 bins (a table is 0.7 m up)
  constexpr double kMinShare = 0.15;  // of the heights, within a bin either side of a level
  if (heights.empty()) return std::nullopt;
  constexpr double kMaxSpan = 50;  // m of heights binned above the lowest (strays aside)
  std::sort(heights.begin(), heights.end());
  const std::size_t strays = heights.size() / 100;  // at either end: kept out of the bins
  const double lowest = heights[strays];
  const double highest = std::min(heights[heights.size() - 1 - strays], lowest + kMaxSpan);
  const double median = heights[heights.size() / 2];
  std::vector<std::size_t> bins(static_cast<std::size_t>((highest - lowest) / kBin) + 3);
  for (const double h : heights)
    if (h >= lowest && h <= highest) ++bins[static_cast<std::size_t>((h - lowest) / kBin) + 1];
  const double needed = kMinShare * static_cast<double>(heights.size());
  for (std::size_t b = 1; b + 1 < bins.size(); ++b) {
    if (static_cast<double>(bins[b - 1] + bins[b] + bins[b + 1]) < needed) continue;
    while (b + 2 < bins.size() && bins[b + 1] > bins[b]) ++b;  // up to the level's peak
    const double level = lowest + (static_cast<double>(b) - 0.5) * kBin;
    if (std::fabs(level - median) <= 2 * kBin) return median;  // one level
    return median_between(heights, level - 1.5 * kBin, level + 1.5 * kBin);
  }
  return median;
}

std::optional<double> floor_height(const LabelledViews& views, const Eigen::Vector3d& up) {
  std::vector<double> heights;
  for (std::size_t i = 0; i < views.points().size(); ++i)
    if (views.labels()[i] == SemanticClass::floor) heights.push_back(views.points()[i].dot(up));
  return floor_level(std::move(heights));
}

}  // namespace kartograf::semantic
