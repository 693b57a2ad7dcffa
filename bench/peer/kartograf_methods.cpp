// Kartograf's side of the peer benchmark: projective point-to-plane ICP between two frames (the
// IcpEngine with its defaults) per backend, the full RGB-D odometry (chained runs), and k-d tree
// ICP on the shared clouds.
#include <memory>
#include <optional>
#include <span>
#include <utility>

#include "kartograf/compute/context.hpp"
#include "kartograf/geometry/subsample.hpp"
#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf_contexts.hpp"
#include "peer_methods.hpp"

namespace kartograf::peer {
namespace {

// One new frame per track(): depth upload, back-projection, the 3-level pyramid with normals, and
// IcpEngine::align against the reference pyramid, which stays on the device.
class KartografOdometry : public OdometryFrontEnd {
 public:
  KartografOdometry(ContextPtr context, const Dataset& dataset)
      : context_(std::move(context)),
        projector_(*context_, dataset.camera(), dataset.range),
        depth_(*context_, dataset.camera().width, dataset.camera().height),
        pyramids_{registration::FramePyramid(*context_, dataset.camera()),
                  registration::FramePyramid(*context_, dataset.camera())},
        engine_(*context_) {}

  void set_reference(const Frame& frame) override {
    build(reference(), frame);
    context_->finish();
  }
  Estimate track(const Frame& frame) override {
    build(current(), frame);
    const registration::IcpResult result = engine_.align(current(), reference());
    return {result.source_to_target, result.inlier_count > 0};
  }
  void advance() override { reference_index_ = 1 - reference_index_; }

 private:
  registration::FramePyramid& reference() { return pyramids_[reference_index_]; }
  registration::FramePyramid& current() { return pyramids_[1 - reference_index_]; }
  void build(registration::FramePyramid& pyramid, const Frame& frame) {
    depth_.upload(frame.depth);
    pyramid.build(projector_, depth_);
  }

  ContextPtr context_;
  geometry::DepthBackprojector projector_;
  compute::DeviceImage<std::uint16_t> depth_;
  registration::FramePyramid pyramids_[2];
  int reference_index_ = 0;
  registration::IcpEngine engine_;
};

OdometryFactory odometry_factory(ContextPtr context) {
  return [context](const Dataset& dataset) -> std::unique_ptr<OdometryFrontEnd> {
    return std::make_unique<KartografOdometry>(context, dataset);
  };
}

// Single-level point-to-plane ICP over unorganized clouds with a k-d tree of the target (built
// inside align(), so it is timed), optionally gating pairs by colour (hue and saturation).
Method cloud_icp(const char* name, InputKind input, const CloudIcpSettings& settings,
                 bool color_gate, ContextPtr context) {
  registration::IcpParams params;
  params.levels = {{settings.max_iterations, 1, settings.max_distance, settings.max_distance, 0}};
  std::unique_ptr<registration::CorrespondenceFinder> finder =
      std::make_unique<registration::KdTreeCorrespondences>(*context);
  if (color_gate) {
    finder = std::make_unique<registration::ColorGatedFinder>(*context, std::move(finder));
  }
  auto engine = std::make_shared<registration::IcpEngine>(*context, params, std::move(finder));

  Method method;
  method.name = name;
  method.library = "kartograf";
  method.input = input;
  method.threads = kartograf_threads();
  method.prepare = [context, engine, input, color_gate](const FramePair& pair) {
    const auto& source =
        input == InputKind::cloud_full ? pair.source_clouds.full : pair.source_clouds.sampled;
    const auto& target =
        input == InputKind::cloud_full ? pair.target_clouds.full : pair.target_clouds.sampled;
    struct Clouds {
      geometry::DeviceCloud source, target;
    };
    auto clouds =
        std::make_shared<Clouds>(Clouds{geometry::DeviceCloud::from_host(*context, source),
                                        geometry::DeviceCloud::from_host(*context, target)});
    return std::function<Estimate()>([engine, clouds, color_gate] {
      const auto view = [color_gate](const geometry::DeviceCloud& cloud) {
        return registration::CloudView{&cloud.points, &cloud.normals,
                                       color_gate ? &cloud.colors : nullptr, std::nullopt};
      };
      const registration::CloudView source_view = view(clouds->source);
      const registration::CloudView target_view = view(clouds->target);
      const registration::IcpResult result =
          engine->align(std::span(&source_view, 1), std::span(&target_view, 1));
      return Estimate{result.source_to_target, result.inlier_count > 0};
    });
  };
  return method;
}

// The whole odometry of `kartograf odometry` (registration/odometry.hpp: motion model, depth
// weights, re-estimation against frame n-5), chained only: it keeps its own frames, so track()
// returns the motion from the pose it returned last to the (re-estimated) pose of the new frame,
// and the chained trajectory equals the odometry's poses frame by frame.
class KartografRgbdOdometry : public OdometryFrontEnd {
 public:
  KartografRgbdOdometry(ContextPtr context, const Dataset& dataset)
      : context_(std::move(context)), camera_(dataset.camera()), range_(dataset.range) {}

  void set_reference(const Frame& frame) override {
    registration::OdometryParams params;
    params.depth_range = range_;
    odometry_.emplace(*context_, camera_, params);
    odometry_->track(frame.depth, &frame.color);
    last_ = Eigen::Isometry3d::Identity();
  }
  Estimate track(const Frame& frame) override {
    const registration::OdometryFrame& report = odometry_->track(frame.depth, &frame.color);
    const Eigen::Isometry3d pose = odometry_->poses().back();
    const Eigen::Isometry3d motion = last_.inverse() * pose;
    last_ = pose;
    return {motion, !report.fallback};
  }
  void advance() override {}

 private:
  ContextPtr context_;
  PinholeIntrinsics camera_;
  geometry::DepthRange range_;
  std::optional<registration::RgbdOdometry> odometry_;
  Eigen::Isometry3d last_ = Eigen::Isometry3d::Identity();
};

}  // namespace

OdometryFactory kartograf_rgbd_odometry_factory() {
  return [context = make_context(compute::BackendChoice::cpu)](
             const Dataset& dataset) -> std::unique_ptr<OdometryFrontEnd> {
    return std::make_unique<KartografRgbdOdometry>(context, dataset);
  };
}

OdometryFactory kartograf_odometry_factory() {
  return odometry_factory(make_context(compute::BackendChoice::cpu));
}

std::vector<Method> kartograf_methods(const CloudIcpSettings& settings, bool device_backends) {
  const ContextPtr cpu = make_context(compute::BackendChoice::cpu);
  std::vector<Method> methods;
  methods.push_back(odometry_method(kKartografOdometry, "kartograf", kartograf_threads(), "",
                                    odometry_factory(cpu)));
  methods.push_back(odometry_method("kartograf p2plane odometry, both frames (cpu)", "kartograf",
                                    kartograf_threads(), "", odometry_factory(cpu), true));
  if (device_backends) {
    // CPU-hosted drivers here (lavapipe, PoCL): for the record, not a speed claim.
    for (const DeviceContext& device : device_contexts()) {
      methods.push_back(odometry_method("kartograf p2plane odometry (" + device.label + ")",
                                        "kartograf", "driver's own", kKartografOdometry,
                                        odometry_factory(device.context)));
    }
  }
  methods.push_back(cloud_icp(kKartografCloudFull, InputKind::cloud_full, settings, false, cpu));
  methods.push_back(
      cloud_icp(kKartografCloudSampled, InputKind::cloud_sampled, settings, false, cpu));
  methods.push_back(
      cloud_icp(kKartografColorSampled, InputKind::cloud_sampled, settings, true, cpu));
  return methods;
}

}  // namespace kartograf::peer
