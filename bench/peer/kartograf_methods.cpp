// Kartograf's side of the peer benchmark: projective point-to-plane odometry (the IcpEngine with
// its defaults, what odometry runs every frame) per backend, and k-d tree ICP on the shared clouds.
#include <memory>
#include <span>
#include <utility>

#include "kartograf/compute/backend.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/geometry/subsample.hpp"
#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "peer_methods.hpp"

namespace kartograf::peer {
namespace {

using ContextPtr = std::shared_ptr<const compute::Context>;

ContextPtr make_context(compute::BackendChoice backend) {
  compute::ContextOptions options;
  options.backend = backend;
  return std::make_shared<const compute::Context>(options);
}

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

}  // namespace

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
    for (const auto& status : compute::probe_backends()) {
      if (status.backend == compute::BackendKind::cpu || !status.available) continue;
      const auto choice = status.backend == compute::BackendKind::vulkan
                              ? compute::BackendChoice::vulkan
                              : compute::BackendChoice::opencl;
      const ContextPtr context = make_context(choice);
      methods.push_back(odometry_method(
          "kartograf p2plane odometry (" + std::string(compute::to_string(status.backend)) + ": " +
              context->device_info().name + ")",
          "kartograf", "driver's own", kKartografOdometry, odometry_factory(context)));
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
