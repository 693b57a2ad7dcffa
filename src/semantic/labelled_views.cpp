#include "kartograf/semantic/labelled_views.hpp"

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

}  // namespace kartograf::semantic
