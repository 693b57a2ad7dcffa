#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <array>
#include <memory>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/features/orb_front_end.hpp"
#include "kartograf/pipeline/mapper.hpp"
#include "kartograf/pipeline/tracking_choices.hpp"
#include "map_dicts.hpp"
#include "reports.hpp"
#include "sequence_handle.hpp"

namespace kartograf::python {

namespace {

nb::dict run_slam(const compute::Context& context, const SequenceHandle& sequence,
                  const pipeline::TrackingChoices& choices, bool loop_closure, bool features,
                  bool build_map, double voxel) {
  mapping::SlamParams params;
  params.odometry = pipeline::odometry_params(choices);
  params.model = pipeline::model_tracking_params(choices);
  params.loop_closure = loop_closure;
  params.build_map = build_map;
  params.map.voxel_size = voxel;
  if (features) {
    params.features = std::make_shared<const features::OrbFrontEnd>(pipeline::map_orb_params());
    params.odometry.features = params.features;
  }
  const auto source = sequence.source();
  mapping::SlamResult result;
  {
    nb::gil_scoped_release unlocked;
    result = mapping::run_slam(context, *source, params);
  }
  nb::dict d;
  d["poses"] = pose_stack(result.poses);
  d["odometry"] = odometry_run_dict(result.odometry);
  std::size_t accepted = 0;
  for (const mapping::LoopClosureRecord& r : result.loop_closures)
    accepted += r.closure.report.accepted() && !r.pruned ? 1 : 0;
  d["loop_closures"] = accepted;
  d["loop_candidates"] = result.loop_candidates;
  d["graph_edges"] = result.graph_edges;
  d["total_seconds"] = result.timing.total_seconds;
  d["map"] = cloud_dict(result.map);
  d["ground_truth"] = optional_poses(source->ground_truth());
  return d;
}

}  // namespace

void bind_mapping(nb::module_& m) {
  const pipeline::TrackingChoices defaults;
  m.def(
      "run_slam",
      [](const compute::Context& context, const SequenceHandle& sequence, const std::string& method,
         int reestimate_every, const std::array<double, 3>& anchor_bounds,
         const std::string& tracking, double model_voxel, bool loop_closure, bool features,
         bool build_map, double voxel) {
        return run_slam(context, sequence,
                        {method, reestimate_every, anchor_bounds, tracking, model_voxel},
                        loop_closure, features, build_map, voxel);
      },
      nb::arg("context"), nb::arg("sequence"), nb::arg("method") = defaults.method,
      nb::arg("reestimate_every") = defaults.reestimate_interval,
      nb::arg("anchor_bounds") = defaults.anchor_bounds, nb::arg("tracking") = defaults.tracking,
      nb::arg("model_voxel") = defaults.model_voxel, nb::arg("loop_closure") = true,
      nb::arg("features") = false, nb::arg("build_map") = false,
      nb::arg("voxel") = mapping::MapFusionParams{}.voxel_size);
  bind_mapper(m);
}

}  // namespace kartograf::python
