// Kartograf's side of the plane comparison: segmentation::PlaneExtractor in each mode with its
// defaults (regions: Lab region growing, per-segment plane fits, merging, pixel refinement;
// cells: planar cells merged, pixels assigned per cell), one extractor per camera kept across
// frames as a caller keeps it across a sequence.
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

std::string settings_text(const segmentation::PlaneExtractionParams& p) {
  std::ostringstream settings;
  if (p.mode == segmentation::PlaneExtractionMode::cells) {
    settings << "cells mode: " << p.cells.cell_size
             << " px cells of 2 x 2 blocks, planar when >= " << 100 * p.cells.min_valid_fraction
             << " % valid, at most half a side of depth jumps (" << 100 * p.growing.max_depth_jump
             << " % and " << p.cells.jump_per_z2 << " z^2), RMS <= " << 1000 * p.cells.rms_base
             << " mm + " << 1000 * p.cells.rms_per_z2
             << " mm z^2; merging over cell and block adjacency; pixels assigned per cell in "
             << p.cells.reach_passes << " passes; planes of at least " << p.min_plane_pixels
             << " pixels; colour only to join planes apart";
    return settings.str();
  }
  settings << "regions mode (defaults): Lab threshold " << p.growing.lab_threshold << ", "
           << p.growing.tile_size << " px tiles, depth jump " << 100 * p.growing.max_depth_jump
           << " %, merging over pixel adjacency, pixel refinement, planes of at least "
           << p.min_plane_pixels << " pixels; uses the colour (Lab growing)";
  return settings.str();
}

// depth_only: the frames' colour is not handed over (a depth camera alone; cells mode).
PlaneMethod extractor_method(std::string name, std::string threads, ContextPtr context,
                             segmentation::PlaneExtractionMode mode, bool depth_only = false) {
  using CameraKey = std::tuple<int, int, double, double, double, double>;
  struct State {
    std::map<CameraKey, std::unique_ptr<segmentation::PlaneExtractor>> extractors;
    segmentation::PlaneSet last;
  };
  auto state = std::make_shared<State>();
  segmentation::PlaneExtractionParams params;
  params.mode = mode;
  PlaneMethod method;
  method.name = std::move(name);
  method.library = "kartograf";
  method.threads = std::move(threads);
  method.settings =
      settings_text(params) + (depth_only ? "; given no colour (depth only): planes apart "
                                            "joined on geometry and the see-through test"
                                          : "");
  method.prepare = [state, context, params, depth_only](const PlaneFrame& frame) {
    const PinholeIntrinsics& c = frame.camera;
    auto& extractor = state->extractors[{c.width, c.height, c.fx, c.fy, c.cx, c.cy}];
    // Made untimed on first use (device buffers, scratch); every frame reuses it.
    if (!extractor) extractor = std::make_unique<segmentation::PlaneExtractor>(*context, c, params);
    segmentation::PlaneExtractor* planes = extractor.get();
    return PlaneRun{
        [state, planes, &frame, depth_only] {
          state->last = planes->extract(frame.points, depth_only ? RgbImage() : frame.color);
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
  using segmentation::PlaneExtractionMode;
  std::vector<PlaneMethod> methods;
  const ContextPtr cpu = make_context(compute::BackendChoice::cpu);
  // The CPU rows run side by side too, each instance with its own context and extractor.
  const auto cpu_method = [&](std::string name, PlaneExtractionMode mode, bool depth_only) {
    PlaneMethod method = extractor_method(name, kartograf_threads(), cpu, mode, depth_only);
    method.another = [name, mode, depth_only] {
      return extractor_method(name, kartograf_threads(), make_context(compute::BackendChoice::cpu),
                              mode, depth_only);
    };
    methods.push_back(std::move(method));
  };
  cpu_method(kKartografPlanes, PlaneExtractionMode::regions, false);
  cpu_method(kKartografCellPlanes, PlaneExtractionMode::cells, false);
  cpu_method("kartograf PlaneExtractor cells, depth only (cpu)", PlaneExtractionMode::cells, true);
  if (device_backends) {
    // CPU-hosted drivers here (lavapipe, PoCL): for the record, not a speed claim.
    for (const DeviceContext& device : device_contexts()) {
      methods.push_back(extractor_method("kartograf PlaneExtractor (" + device.label + ")",
                                         "driver's own", device.context,
                                         PlaneExtractionMode::regions));
      methods.push_back(extractor_method("kartograf PlaneExtractor cells (" + device.label + ")",
                                         "driver's own", device.context,
                                         PlaneExtractionMode::cells));
    }
  }
  return methods;
}

}  // namespace kartograf::peer
