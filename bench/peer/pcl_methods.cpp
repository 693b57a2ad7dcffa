// PCL's side of the peer benchmark (Debian's libpcl-dev 1.13): IterativeClosestPoint
// (point-to-point, SVD) and GeneralizedIterativeClosestPoint (plane-to-plane, its covariances from
// 20 neighbours computed inside align(), so timed), single-threaded, on the downsampled clouds.
// Both stop after CloudIcpSettings::max_iterations or when an update moves less than 1e-8
// (PCL's transformation epsilon: squared translation, 1 - cos of the rotation).
#include <memory>

#include <pcl/pcl_config.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>

#include "peer_methods.hpp"

namespace kartograf::peer {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr to_pcl(const PointCloud& cloud) {
  auto result = std::make_shared<Cloud>();
  result->reserve(cloud.size());
  for (const auto& p : cloud.points) result->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return result;
}

template <class Registration>
Method registration_method(const char* name, const CloudIcpSettings& settings) {
  Method method;
  method.name = name;
  method.library = "pcl";
  method.input = InputKind::cloud_sampled;
  method.threads = "1 (PCL 1.13 registration is single-threaded)";
  method.compared_with = kKartografCloudSampled;
  method.prepare = [settings](const FramePair& pair) {
    const Cloud::Ptr source = to_pcl(pair.source_clouds.sampled);
    const Cloud::Ptr target = to_pcl(pair.target_clouds.sampled);
    return std::function<Estimate()>([source, target, settings] {
      // A fresh object per call: nothing (k-d tree, covariances) is carried over between calls.
      Registration registration;
      registration.setInputSource(source);
      registration.setInputTarget(target);
      registration.setMaxCorrespondenceDistance(settings.max_distance);
      registration.setMaximumIterations(settings.max_iterations);
      registration.setTransformationEpsilon(1e-8);
      Cloud aligned;
      registration.align(aligned);
      return Estimate{
          Eigen::Isometry3d(registration.getFinalTransformation().template cast<double>()),
          registration.hasConverged()};
    });
  };
  return method;
}

}  // namespace

std::vector<Method> pcl_methods(const CloudIcpSettings& settings) {
  return {
      registration_method<pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>>(
          "pcl ICP (point-to-point) 20k", settings),
      registration_method<pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>>(
          "pcl GICP 20k", settings),
  };
}

std::string pcl_version() {
  return PCL_VERSION_PRETTY;
}

}  // namespace kartograf::peer
