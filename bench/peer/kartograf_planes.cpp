// Kartograf's side of the plane comparison: segmentation::PlaneExtractor with its defaults (Lab
// region growing, per-segment plane fits, merging, pixel refinement), one extractor per camera
// kept across frames as a caller keeps it across a sequence.
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf_contexts.hpp"
#include "peer_methods.hpp"
#include "plane_methods.hpp"

namespace kartograf::peer {
namespace {

PlaneMethod extractor_method(std::string name, std::string threads, ContextPtr context) {
  using CameraKey = std::tuple<int, int, double, double, double, double>;
  struct State {
    std::map<CameraKey, std::unique_ptr<segmentation::PlaneExtractor>> extractors;
    segmentation::PlaneSet last;
  };
  auto state = std::make_shared<State>();
  const segmentation::PlaneExtractionParams defaults;
  PlaneMethod method;
  method.name = std::move(name);
  method.library = "kartograf";
  method.threads = std::move(threads);
  std::ostringstream settings;
  settings << "defaults: Lab threshold " << defaults.growing.lab_threshold << ", "
           << defaults.growing.tile_size << " px tiles, depth jump "
           << 100 * defaults.growing.max_depth_jump
           << " %, merging over pixel adjacency, pixel refinement, planes of at least "
           << defaults.min_plane_pixels << " pixels; uses the colour (Lab growing)";
  method.settings = settings.str();
  method.prepare = [state, context](const PlaneFrame& frame) {
    const PinholeIntrinsics& c = frame.camera;
    auto& extractor = state->extractors[{c.width, c.height, c.fx, c.fy, c.cx, c.cy}];
    // Made untimed on first use (device buffers, scratch); every frame reuses it.
    if (!extractor) extractor = std::make_unique<segmentation::PlaneExtractor>(*context, c);
    segmentation::PlaneExtractor* planes = extractor.get();
    return PlaneRun{
        [state, planes, &frame] {
          state->last = planes->extract(frame.points, frame.color);
          const segmentation::PlaneExtractionTimings& t = state->last.timings;
          return TimeParts{
              {"lab", t.lab},         {"growing", t.growing},       {"moments", t.moments},
              {"merging", t.merging}, {"refinement", t.refinement}, {"output", t.output}};
        },
        [state] {
          PlaneOutput output{state->last.labels, {}};
          for (const segmentation::Plane& plane : state->last.planes)
            output.normals[plane.id] = plane.normal;
          return output;
        }};
  };
  return method;
}

}  // namespace

std::vector<PlaneMethod> kartograf_plane_methods(bool device_backends) {
  std::vector<PlaneMethod> methods;
  methods.push_back(extractor_method(kKartografPlanes, kartograf_threads(),
                                     make_context(compute::BackendChoice::cpu)));
  if (device_backends) {
    // CPU-hosted drivers here (lavapipe, PoCL): for the record, not a speed claim.
    for (const DeviceContext& device : device_contexts()) {
      methods.push_back(extractor_method("kartograf PlaneExtractor (" + device.label + ")",
                                         "driver's own", device.context));
    }
  }
  return methods;
}

}  // namespace kartograf::peer
