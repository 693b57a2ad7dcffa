#include "kartograf/mapping/plane_map.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace {

double box_gap(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
  const Eigen::Vector3d gap =
      (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(Eigen::Vector3d::Zero());
  return gap.norm();
}

}  // namespace

void PlaneMapParams::validate() const {
  auto check = [](bool ok, const std::string& field) {
    require(ok, "PlaneMapParams: " + field + " is out of range");
  };
  check(
      std::isfinite(max_normal_angle_deg) && max_normal_angle_deg > 0 && max_normal_angle_deg < 90,
      "max_normal_angle_deg (0, 90)");
  check(std::isfinite(max_offset) && max_offset > 0, "max_offset (> 0)");
  check(std::isfinite(max_gap) && max_gap >= 0, "max_gap (>= 0)");
  check(point_stride >= 1, "point_stride (>= 1)");
}

PlaneMap::PlaneMap(const PlaneMapParams& params) : params_(params) {
  params_.validate();
}

void PlaneMap::refit(Accumulator& a, const Eigen::Vector3d& anchor) {
  const double n = static_cast<double>(a.count);
  const Eigen::Vector3d mean = a.sum / n;
  const Eigen::Matrix3d covariance = a.outer / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (normal.dot(a.normal) < 0) normal = -normal;  // keep the side it was seen from
  a.normal = normal;
  a.offset = -normal.dot(anchor + mean);
}

bool PlaneMap::joins(const Accumulator& a, const Accumulator& b) const {
  const double min_cos = std::cos(params_.max_normal_angle_deg * M_PI / 180.0);
  if (a.normal.dot(b.normal) < min_cos) return false;
  // The smaller one's centroid against the larger one's plane: the larger fit is the better one.
  const Accumulator& large = a.count >= b.count ? a : b;
  const Accumulator& small = a.count >= b.count ? b : a;
  const Eigen::Vector3d centroid = anchor_ + small.sum / static_cast<double>(small.count);
  if (std::fabs(large.normal.dot(centroid) + large.offset) > params_.max_offset) return false;
  return box_gap(a.box, b.box) <= params_.max_gap;
}

void PlaneMap::absorb(Accumulator& into, Accumulator& from) const {
  into.sum += from.sum;
  into.outer += from.outer;
  into.count += from.count;
  into.box.extend(from.box);
  into.kept.insert(into.kept.end(), from.kept.begin(), from.kept.end());
  for (std::size_t c = 0; c < into.votes.size(); ++c) into.votes[c] += from.votes[c];
  into.views += from.views;
  refit(into, anchor_);
}

void PlaneMap::add_view(const segmentation::PlaneSet& planes, const PointImage& points,
                        const SemanticImage& labels, const Eigen::Isometry3d& sensor_to_world) {
  const LabelImage& ids = planes.labels;
  require(ids.width() == points.width() && ids.height() == points.height(),
          "PlaneMap: plane labels and points differ in size");
  require(
      labels.empty() || (labels.width() == points.width() && labels.height() == points.height()),
      "PlaneMap: semantic labels and points differ in size");
  if (planes.planes.empty()) return;
  if (!anchored_) {
    anchor_ = sensor_to_world.translation();
    anchored_ = true;
  }
  std::vector<Accumulator> view(planes.planes.size());
  for (std::size_t k = 0; k < view.size(); ++k) {
    view[k].normal = sensor_to_world.linear() * planes.planes[k].normal;
    view[k].views = 1;
  }
  for (int y = 0; y < ids.height(); ++y) {
    for (int x = 0; x < ids.width(); ++x) {
      const Label id = ids(x, y);
      const Point4f& p = points(x, y);
      if (id == 0 || id > view.size() || !is_valid(p)) continue;
      Accumulator& a = view[id - 1];
      const Eigen::Vector3d world = sensor_to_world * p.head<3>().cast<double>();
      const Eigen::Vector3d local = world - anchor_;
      a.sum += local;
      a.outer += local * local.transpose();
      ++a.count;
      a.box.extend(world);
      if (x % params_.point_stride == 0 && y % params_.point_stride == 0)
        a.kept.push_back(world.cast<float>());
      if (!labels.empty()) ++a.votes[static_cast<std::size_t>(labels(x, y))];
    }
  }
  for (Accumulator& a : view) {
    if (a.count < 3) continue;
    refit(a, anchor_);
    auto match = std::find_if(planes_.begin(), planes_.end(),
                              [&](const Accumulator& m) { return joins(m, a); });
    if (match != planes_.end()) {
      absorb(*match, a);
    } else {
      planes_.push_back(std::move(a));
    }
  }
}

std::vector<MapPlane> PlaneMap::planes(const Eigen::Isometry3d& transform) {
  // Map planes that grew into each other (a wall seen first in two separate pieces) become one.
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < planes_.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < planes_.size(); ++j) {
        if (!joins(planes_[i], planes_[j])) continue;
        absorb(planes_[i], planes_[j]);
        planes_.erase(planes_.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
        break;
      }
    }
  }
  std::vector<MapPlane> out;
  for (const Accumulator& a : planes_) {
    if (a.count < params_.min_points) continue;
    const double n = static_cast<double>(a.count);
    const Eigen::Vector3d mean = a.sum / n;
    const Eigen::Matrix3d covariance = a.outer / n - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    MapPlane plane;
    plane.normal = transform.linear() * a.normal;
    plane.centroid = transform * (anchor_ + mean);
    plane.offset = -plane.normal.dot(plane.centroid);
    plane.major_axis = transform.linear() * solver.eigenvectors().col(2);
    plane.minor_axis = plane.normal.cross(plane.major_axis).normalized();
    plane.major_axis = plane.minor_axis.cross(plane.normal);
    Eigen::Vector2d low = Eigen::Vector2d::Constant(INFINITY), high = -low;
    for (const Eigen::Vector3f& kept : a.kept) {
      const Eigen::Vector3d d = transform * kept.cast<double>() - plane.centroid;
      const Eigen::Vector2d uv(d.dot(plane.major_axis), d.dot(plane.minor_axis));
      low = low.cwiseMin(uv);
      high = high.cwiseMax(uv);
    }
    if (a.kept.empty()) low = high = Eigen::Vector2d::Zero();
    plane.extent_min = low;
    plane.extent_max = high;
    plane.area = (high - low).prod();
    plane.point_count = a.count;
    plane.rms_error = std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
    plane.views = a.views;
    const auto best = std::max_element(a.votes.begin(), a.votes.end());
    if (*best > 0) plane.label = static_cast<SemanticClass>(best - a.votes.begin());
    out.push_back(plane);
  }
  std::stable_sort(out.begin(), out.end(), [](const MapPlane& a, const MapPlane& b) {
    return a.point_count > b.point_count;
  });
  for (std::size_t i = 0; i < out.size(); ++i) out[i].id = static_cast<int>(i + 1);
  return out;
}

}  // namespace kartograf::mapping
