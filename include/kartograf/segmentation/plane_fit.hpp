#pragma once
// Plane fits per segment from its moments (docs/methods.md M1 step 3). The default is the
// total-least-squares plane (through the centroid, normal = eigenvector of the covariance with the
// smallest eigenvalue), which handles every orientation; the paper's eq. 6 (z = A x + B y + C,
// singular for planes parallel to the z axis) is kept as an option. The moments are accumulated by
// geometry::SegmentMomentReducer, so on Vulkan/OpenCL they are summed on the device.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/geometry/segment_moments.hpp"

namespace kartograf::segmentation {

enum class PlaneFitMethod : std::uint8_t {
  total_least_squares,  // smallest eigenvector of the covariance
  paper_eq6,            // least squares z = A x + B y + C (fails for vertical planes)
};

struct PlaneFitParams {
  PlaneFitMethod method = PlaneFitMethod::total_least_squares;
  std::uint64_t min_points = 3;  // fewer points: no fit
  // Collinear or coincident points: the middle eigenvalue of the covariance (in-plane spread
  // squared along the minor axis) at most this fraction of the largest.
  double degenerate_ratio = 1e-6;
};

// A fitted plane n . p + offset = 0, with n of unit length pointing towards the camera (the
// origin of the points' frame): n . centroid < 0 and offset >= 0.
struct SegmentPlane {
  bool valid = false;  // false: too few points or a degenerate fit (the other fields are zero)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::uint64_t count = 0;
  double rms_error = 0;  // RMS point-plane distance of the segment's points, from the moments
  // In-plane axes (unit; major spread first): with normal they form a right-handed basis.
  Eigen::Vector3d major_axis = Eigen::Vector3d::Zero();
  Eigen::Vector3d minor_axis = Eigen::Vector3d::Zero();
  // Standard deviation of the points along each in-plane axis [m] (a uniform strip of width w
  // has w / sqrt(12)).
  double major_sigma = 0;
  double minor_sigma = 0;
};

// Moments relative to `origin` (a geometry::SegmentMomentSet's origin).
SegmentPlane fit_plane(const geometry::SegmentMoments& moments, const Eigen::Vector3d& origin,
                       const PlaneFitParams& params = {});

// Mean squared distance of the points summarised by `moments` to the plane n . p + offset = 0
// (exact from the moments: n^T S n + (n . c + offset)^2 with S their covariance, c their centroid).
double mean_squared_distance(const geometry::SegmentMoments& moments, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& normal, double offset);

// Moments of every segment of a cloud, accumulated on the context's backend. Handles any number
// of labels (the device reducer takes 65,536 per pass; more run in several passes). Keeps its
// device buffers between frames.
class SegmentPlaneFitter {
 public:
  explicit SegmentPlaneFitter(const compute::Context& context);

  // points (on this context) and labels (host; 0..segment_count-1 or kNoLabel) have the same
  // length; moments are taken about `origin`, and every valid point lies within max_offset of it
  // per coordinate. Throws Error on bad input.
  geometry::SegmentMomentSet moments(const compute::Buffer<Point4f>& points,
                                     std::span<const std::uint32_t> labels,
                                     std::uint32_t segment_count, const Eigen::Vector3f& origin,
                                     float max_offset);
  // The same with the labels already on this context (device_labels; host_labels holds the same
  // values, read only when there are more labels than one device pass takes).
  geometry::SegmentMomentSet moments(const compute::Buffer<Point4f>& points,
                                     const compute::Buffer<std::uint32_t>& device_labels,
                                     std::span<const std::uint32_t> host_labels,
                                     std::uint32_t segment_count, const Eigen::Vector3f& origin,
                                     float max_offset);

 private:
  const compute::Context* context_;
  geometry::SegmentMomentReducer reducer_;
  compute::Buffer<std::uint32_t> labels_;
  std::vector<std::uint32_t> chunk_;  // host labels of one pass when there are > 65,536
};

std::vector<SegmentPlane> fit_planes(const geometry::SegmentMomentSet& moments,
                                     const PlaneFitParams& params = {});

}  // namespace kartograf::segmentation
