#include "kartograf/segmentation/plane_fit.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace kartograf::segmentation {

namespace {

Eigen::Matrix3d covariance_of(const geometry::SegmentMoments& m) {
  const double n = static_cast<double>(m.count);
  const Eigen::Vector3d mean = m.sum / n;
  return m.sum_outer / n - mean * mean.transpose();
}

// Turns the normal towards the camera (the origin) and completes the plane from the centroid.
void orient_and_finish(const Eigen::Vector3d& normal, const Eigen::Vector3d& major,
                       const Eigen::Matrix3d& covariance, SegmentPlane& plane) {
  const double sign = normal.dot(plane.centroid) > 0.0 ? -1.0 : 1.0;
  plane.normal = sign * normal;
  plane.offset = -plane.normal.dot(plane.centroid);
  plane.rms_error = std::sqrt(std::max(0.0, plane.normal.dot(covariance * plane.normal)));
  // In-plane axes: the major direction made orthogonal to the normal (eq. 6 normals are not
  // exactly eigenvectors), then normal x major.
  Eigen::Vector3d u = major - major.dot(plane.normal) * plane.normal;
  if (u.squaredNorm() < 1e-24) u = plane.normal.unitOrthogonal();
  plane.major_axis = u.normalized();
  plane.minor_axis = plane.normal.cross(plane.major_axis);
  plane.major_sigma = std::sqrt(std::max(0.0, plane.major_axis.dot(covariance * plane.major_axis)));
  plane.minor_sigma = std::sqrt(std::max(0.0, plane.minor_axis.dot(covariance * plane.minor_axis)));
  plane.valid = true;
}

}  // namespace

SegmentPlane fit_plane(const geometry::SegmentMoments& moments, const Eigen::Vector3d& origin,
                       const PlaneFitParams& params) {
  SegmentPlane plane;
  plane.count = moments.count;
  if (moments.count < std::max<std::uint64_t>(params.min_points, 3)) return plane;
  const double n = static_cast<double>(moments.count);
  const Eigen::Matrix3d covariance = covariance_of(moments);
  const Eigen::Vector3d centroid = origin + moments.sum / n;

  // The closed-form 3x3 solver: several times faster than the iterative one, and accurate here
  // (the plane's normal is the eigenvector of the smallest eigenvalue of a well-separated trio).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d eigenvalues = solver.eigenvalues();  // ascending
  if (!(eigenvalues(2) > 0.0) || eigenvalues(1) <= params.degenerate_ratio * eigenvalues(2)) {
    return plane;  // coincident or collinear points: no unique plane
  }
  SegmentPlane fitted = plane;
  fitted.centroid = centroid;
  const Eigen::Vector3d major = solver.eigenvectors().col(2);
  if (params.method == PlaneFitMethod::total_least_squares) {
    orient_and_finish(solver.eigenvectors().col(0), major, covariance, fitted);
    return fitted;
  }
  // Eq. 6 about the centroid: [Cxx Cxy; Cxy Cyy] (A, B) = (Cxz, Cyz); the normal is (A, B, -1).
  const Eigen::Matrix2d lhs = covariance.topLeftCorner<2, 2>();
  const double det = lhs.determinant();
  if (!(std::fabs(det) > 1e-12 * std::max(1e-300, lhs.squaredNorm()))) return plane;  // vertical
  const Eigen::Vector2d ab = lhs.inverse() * covariance.block<2, 1>(0, 2);
  orient_and_finish(Eigen::Vector3d(ab(0), ab(1), -1.0).normalized(), major, covariance, fitted);
  return fitted;
}

double mean_squared_distance(const geometry::SegmentMoments& moments, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& normal, double offset) {
  if (moments.count == 0) return 0.0;
  const double n = static_cast<double>(moments.count);
  const double centre_distance = normal.dot(origin + moments.sum / n) + offset;
  return std::max(0.0, normal.dot(covariance_of(moments) * normal)) +
         centre_distance * centre_distance;
}

std::vector<SegmentPlane> fit_planes(const geometry::SegmentMomentSet& moments,
                                     const PlaneFitParams& params) {
  std::vector<SegmentPlane> planes;
  planes.reserve(moments.segments.size());
  for (const geometry::SegmentMoments& m : moments.segments)
    planes.push_back(fit_plane(m, moments.origin, params));
  return planes;
}

SegmentPlaneFitter::SegmentPlaneFitter(const compute::Context& context)
    : context_(&context), reducer_(context) {}

geometry::SegmentMomentSet SegmentPlaneFitter::moments(
    const compute::Buffer<Point4f>& points, const compute::Buffer<std::uint32_t>& device_labels,
    std::span<const std::uint32_t> host_labels, std::uint32_t segment_count,
    const Eigen::Vector3f& origin, float max_offset) {
  require(device_labels.size() == host_labels.size() && points.size() == host_labels.size(),
          "segment plane fit: " + std::to_string(points.size()) + " points but " +
              std::to_string(device_labels.size()) + " device and " +
              std::to_string(host_labels.size()) + " host labels");
  if (segment_count == 0 || segment_count > geometry::kMaxSegmentLabels || points.empty())
    return moments(points, host_labels, segment_count, origin, max_offset);
  geometry::SegmentMomentParams params;
  params.origin = origin;
  params.max_offset = max_offset;
  params.label_count = segment_count;
  return reducer_.run(points, device_labels, params);
}

geometry::SegmentMomentSet SegmentPlaneFitter::moments(const compute::Buffer<Point4f>& points,
                                                       std::span<const std::uint32_t> labels,
                                                       std::uint32_t segment_count,
                                                       const Eigen::Vector3f& origin,
                                                       float max_offset) {
  require(points.size() == labels.size(), "segment plane fit: " + std::to_string(points.size()) +
                                              " points but " + std::to_string(labels.size()) +
                                              " labels");
  geometry::SegmentMomentSet result;
  result.origin = origin.cast<double>();
  if (segment_count == 0 || points.empty()) return result;
  if (labels_.size() != labels.size())
    labels_ = compute::Buffer<std::uint32_t>(*context_, labels.size());

  geometry::SegmentMomentParams params;
  params.origin = origin;
  params.max_offset = max_offset;
  result.segments.reserve(segment_count);
  // One pass per 65,536 labels; a pass sees the others as kNoLabel.
  for (std::uint32_t first = 0; first < segment_count; first += geometry::kMaxSegmentLabels) {
    params.label_count = std::min(segment_count - first, geometry::kMaxSegmentLabels);
    if (first == 0 && segment_count <= geometry::kMaxSegmentLabels) {
      labels_.upload(labels);
    } else {
      chunk_.resize(labels.size());
      for (std::size_t i = 0; i < labels.size(); ++i) {
        if (labels[i] != geometry::kNoLabel && labels[i] >= segment_count) {
          throw Error("segment plane fit: pixel " + std::to_string(i) + " has label " +
                      std::to_string(labels[i]) + " >= segment count " +
                      std::to_string(segment_count));
        }
        const std::uint32_t local = labels[i] - first;  // wraps for labels below `first`
        chunk_[i] = local < params.label_count ? local : geometry::kNoLabel;
      }
      labels_.upload(chunk_);
    }
    geometry::SegmentMomentSet pass = reducer_.run(points, labels_, params);
    for (geometry::SegmentMoments& m : pass.segments) result.segments.push_back(std::move(m));
  }
  return result;
}

}  // namespace kartograf::segmentation
