// Open3D's side of the peer benchmark (Debian's libopen3d-dev 0.16, OpenMP inside: its thread
// count is OMP_NUM_THREADS). Every method runs with Open3D's defaults except the depth range and
// the cloud ICP gate and iteration limit, which all methods share.
#include <cstring>
#include <memory>

#include <open3d/Open3DConfig.h>
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/odometry/Odometry.h>
#include <open3d/pipelines/registration/ColoredICP.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/utility/Logging.h>

#include "peer_methods.hpp"

namespace kartograf::peer {
namespace {

namespace o3d = open3d;

template <class Pixel>
o3d::geometry::Image to_open3d(const Image<Pixel>& image, int channels, int bytes_per_channel) {
  o3d::geometry::Image result;
  result.Prepare(image.width(), image.height(), channels, bytes_per_channel);
  std::memcpy(result.data_.data(), image.data(), result.data_.size());
  return result;
}

// What Open3D's odometry consumes: float depth in metres (cut at the shared range) and float
// intensity. Made from the raw images inside track(), as Open3D's own pipelines do per frame.
std::shared_ptr<o3d::geometry::RGBDImage> to_rgbd(const Frame& frame, const Dataset& dataset) {
  static_assert(sizeof(Rgb8) == 3);
  return o3d::geometry::RGBDImage::CreateFromColorAndDepth(
      to_open3d(frame.color, 3, 1), to_open3d(frame.depth, 1, 2), dataset.range.units_per_metre,
      dataset.range.max_metres, true);
}

// pipelines::odometry::ComputeRGBDOdometry with the hybrid (photometric + geometric) Jacobian,
// default options (20/10/5 iterations per level, 3 cm depth difference) and the shared depth range.
class Open3dOdometry : public OdometryFrontEnd {
 public:
  explicit Open3dOdometry(const Dataset& dataset)
      : dataset_(&dataset),
        camera_(dataset.camera().width, dataset.camera().height, dataset.camera().fx,
                dataset.camera().fy, dataset.camera().cx, dataset.camera().cy) {
    option_.depth_min_ = dataset.range.min_metres;
    option_.depth_max_ = dataset.range.max_metres;
  }

  void set_reference(const Frame& frame) override { reference_ = to_rgbd(frame, *dataset_); }
  Estimate track(const Frame& frame) override {
    current_ = to_rgbd(frame, *dataset_);
    const auto [success, motion, information] = o3d::pipelines::odometry::ComputeRGBDOdometry(
        *current_, *reference_, camera_, Eigen::Matrix4d::Identity(),
        o3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm(), option_);
    (void)information;
    return {Eigen::Isometry3d(motion), success};
  }
  void advance() override { reference_ = current_; }

 private:
  const Dataset* dataset_;
  o3d::camera::PinholeCameraIntrinsic camera_;
  o3d::pipelines::odometry::OdometryOption option_;
  std::shared_ptr<o3d::geometry::RGBDImage> reference_, current_;
};

o3d::geometry::PointCloud to_open3d(const PointCloud& cloud) {
  o3d::geometry::PointCloud result;
  result.points_.reserve(cloud.size());
  for (const auto& p : cloud.points) result.points_.push_back(p.cast<double>());
  for (const auto& n : cloud.normals) result.normals_.push_back(n.cast<double>());
  for (const auto& c : cloud.colors) {
    result.colors_.emplace_back(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
  }
  return result;
}

enum class CloudMetric { point_to_plane, colored };

// RegistrationICP (point-to-plane) or RegistrationColoredICP; both build their k-d tree of the
// target inside the call (timed), as Kartograf's k-d tree ICP does.
Method cloud_icp(const char* name, InputKind input, CloudMetric metric, const char* compared_with,
                 const CloudIcpSettings& settings) {
  Method method;
  method.name = name;
  method.library = "open3d";
  method.input = input;
  method.threads = openmp_threads();
  method.compared_with = compared_with;
  method.prepare = [input, metric, settings](const FramePair& pair) {
    const bool full = input == InputKind::cloud_full;
    auto source = std::make_shared<o3d::geometry::PointCloud>(
        to_open3d(full ? pair.source_clouds.full : pair.source_clouds.sampled));
    auto target = std::make_shared<o3d::geometry::PointCloud>(
        to_open3d(full ? pair.target_clouds.full : pair.target_clouds.sampled));
    return std::function<Estimate()>([source, target, metric, settings] {
      const o3d::pipelines::registration::ICPConvergenceCriteria criteria(1e-6, 1e-6,
                                                                          settings.max_iterations);
      const o3d::pipelines::registration::RegistrationResult result =
          metric == CloudMetric::colored
              ? o3d::pipelines::registration::RegistrationColoredICP(
                    *source, *target, settings.max_distance, Eigen::Matrix4d::Identity(),
                    o3d::pipelines::registration::TransformationEstimationForColoredICP(), criteria)
              : o3d::pipelines::registration::RegistrationICP(
                    *source, *target, settings.max_distance, Eigen::Matrix4d::Identity(),
                    o3d::pipelines::registration::TransformationEstimationPointToPlane(), criteria);
      return Estimate{Eigen::Isometry3d(result.transformation_), result.fitness_ > 0};
    });
  };
  return method;
}

}  // namespace

OdometryFactory open3d_odometry_factory() {
  return [](const Dataset& dataset) -> std::unique_ptr<OdometryFrontEnd> {
    return std::make_unique<Open3dOdometry>(dataset);
  };
}

std::vector<Method> open3d_methods(const CloudIcpSettings& settings) {
  o3d::utility::SetVerbosityLevel(o3d::utility::VerbosityLevel::Error);
  std::vector<Method> methods;
  methods.push_back(odometry_method("open3d RGB-D odometry, hybrid term", "open3d",
                                    openmp_threads(), kKartografOdometry,
                                    open3d_odometry_factory()));
  methods.push_back(cloud_icp("open3d p2plane ICP", InputKind::cloud_full,
                              CloudMetric::point_to_plane, kKartografCloudFull, settings));
  methods.push_back(cloud_icp("open3d p2plane ICP 20k", InputKind::cloud_sampled,
                              CloudMetric::point_to_plane, kKartografCloudSampled, settings));
  methods.push_back(cloud_icp("open3d coloured ICP 20k", InputKind::cloud_sampled,
                              CloudMetric::colored, kKartografColorSampled, settings));
  return methods;
}

std::string open3d_version() {
  return OPEN3D_VERSION;
}

}  // namespace kartograf::peer
