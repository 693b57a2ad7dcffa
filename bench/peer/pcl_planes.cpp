// PCL's side of the plane comparison (Debian's libpcl-dev 1.13, the library's own precompiled
// instantiations for PointXYZRGB: single-threaded, no OpenMP in either class):
// IntegralImageNormalEstimation (COVARIANCE_MATRIX) and OrganizedMultiPlaneSegmentation with the
// parameters of PCL's organized_segmentation_demo, except the minimum plane size, which is
// Kartograf's (the demo's 10000 inliers would drop most planes of a room). The second method adds
// OrganizedMultiPlaneSegmentation::refine, which grows the planes into neighbouring pixels that
// fit their plane, as the demo does by default. Neither computes the region contours
// (segment(regions) / segmentAndRefine(regions)): Kartograf gives none either.
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/common/angles.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>

#include "peer_timing.hpp"
#include "plane_methods.hpp"

namespace kartograf::peer {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGB>;

// The shared organized cloud as PCL expects it: same grid, NaN coordinates where invalid.
Cloud::Ptr to_pcl(const PlaneFrame& frame) {
  auto cloud = std::make_shared<Cloud>(static_cast<std::uint32_t>(frame.points.width()),
                                       static_cast<std::uint32_t>(frame.points.height()));
  cloud->is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < frame.points.size(); ++i) {
    const Point4f& p = frame.points.data()[i];
    pcl::PointXYZRGB& q = (*cloud)[i];
    const bool valid = is_valid(p);
    q.x = valid ? p.x() : nan;
    q.y = valid ? p.y() : nan;
    q.z = valid ? p.z() : nan;
    q.r = frame.color.data()[i][0];
    q.g = frame.color.data()[i][1];
    q.b = frame.color.data()[i][2];
  }
  return cloud;
}

// The demo's normal estimation ("well performing for tabletop objects as imaged by a primesense
// sensor"): covariance of a 20 x 20 px window from integral images, no window across a depth
// change of more than 2 % of the depth.
constexpr float kMaxDepthChangeFactor = 0.02f;
constexpr float kNormalSmoothingSize = 20.0f;
constexpr double kAngularThresholdDeg = 3.0;

using Estimation = pcl::IntegralImageNormalEstimation<pcl::PointXYZRGB, pcl::Normal>;
using Segmentation =
    pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZRGB, pcl::Normal, pcl::Label>;

// One estimator and one segmenter for all frames, as a caller keeps them across a sequence.
struct Segmenter {
  Estimation estimation;
  Segmentation segmentation;
};

// One frame's cloud and, after a call, its planes.
struct Prepared {
  Cloud::Ptr cloud;
  std::vector<pcl::ModelCoefficients> coefficients;
  std::vector<pcl::PointIndices> inliers;
};

TimeParts segment_planes(Segmenter& segmenter, Prepared& prepared, bool refine) {
  Clock::time_point start = Clock::now();
  auto normals = std::make_shared<pcl::PointCloud<pcl::Normal>>();
  segmenter.estimation.setInputCloud(prepared.cloud);
  segmenter.estimation.compute(*normals);
  TimeParts parts{{"normals", 1000 * seconds_since(start)}};

  start = Clock::now();
  prepared.coefficients.clear();
  prepared.inliers.clear();
  std::vector<Eigen::Vector4f, Eigen::aligned_allocator<Eigen::Vector4f>> centroids;
  std::vector<Eigen::Matrix3f, Eigen::aligned_allocator<Eigen::Matrix3f>> covariances;
  auto labels = std::make_shared<pcl::PointCloud<pcl::Label>>();
  std::vector<pcl::PointIndices> label_indices;
  segmenter.segmentation.setInputNormals(normals);
  segmenter.segmentation.setInputCloud(prepared.cloud);
  segmenter.segmentation.segment(prepared.coefficients, prepared.inliers, centroids, covariances,
                                 *labels, label_indices);
  parts.emplace_back("segment", 1000 * seconds_since(start));
  if (refine) {
    start = Clock::now();
    segmenter.segmentation.refine(prepared.coefficients, prepared.inliers, labels, label_indices);
    parts.emplace_back("refine", 1000 * seconds_since(start));
  }
  return parts;
}

PlaneOutput to_output(const Prepared& prepared) {
  // refine() grows planes only into pixels of no plane: a pixel is in at most one inlier list.
  PlaneOutput output{LabelImage(static_cast<int>(prepared.cloud->width),
                                static_cast<int>(prepared.cloud->height), kUnlabeled),
                     {}};
  for (std::size_t k = 0; k < prepared.inliers.size(); ++k) {
    const auto id = static_cast<Label>(k + 1);
    for (const int i : prepared.inliers[k].indices) output.labels.data()[i] = id;
    const std::vector<float>& c = prepared.coefficients[k].values;
    output.normals[id] = Eigen::Vector3d(c[0], c[1], c[2]);
  }
  return output;
}

PlaneMethod omps_method(bool refine) {
  auto segmenter = std::make_shared<Segmenter>();
  segmenter->estimation.setNormalEstimationMethod(Estimation::COVARIANCE_MATRIX);
  segmenter->estimation.setMaxDepthChangeFactor(kMaxDepthChangeFactor);
  segmenter->estimation.setNormalSmoothingSize(kNormalSmoothingSize);
  segmenter->segmentation.setMinInliers(static_cast<unsigned>(kMinPlanePixels));
  segmenter->segmentation.setAngularThreshold(pcl::deg2rad(kAngularThresholdDeg));
  segmenter->segmentation.setDistanceThreshold(kPlaneDistance);

  PlaneMethod method;
  method.name = refine ? "pcl OrganizedMultiPlaneSegmentation + refine"
                       : "pcl OrganizedMultiPlaneSegmentation";
  method.library = "pcl";
  method.threads = "1 (PCL 1.13: no threads in these classes)";
  method.settings =
      "IntegralImageNormalEstimation COVARIANCE_MATRIX, max depth change factor 0.02, smoothing "
      "size 20 (timed, shown as 'normals'); angular threshold 3 deg, distance threshold 0.02 m "
      "(scaled by z^2: PCL's depth-dependent mode), min inliers 300, maximum curvature 0.001 "
      "(default)" +
      std::string(refine ? "; then refine() (PlaneRefinementComparator defaults)" : "");
  method.prepare = [segmenter, refine](const PlaneFrame& frame) {
    auto prepared = std::make_shared<Prepared>();
    prepared->cloud = to_pcl(frame);
    return PlaneRun{
        [segmenter, prepared, refine] { return segment_planes(*segmenter, *prepared, refine); },
        [prepared] { return to_output(*prepared); }};
  };
  return method;
}

}  // namespace

std::vector<PlaneMethod> pcl_plane_methods() {
  return {omps_method(false), omps_method(true)};
}

}  // namespace kartograf::peer
