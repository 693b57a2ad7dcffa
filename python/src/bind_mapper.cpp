#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <array>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/pipeline/mapper.hpp"
#include "map_dicts.hpp"

namespace kartograf::python {

namespace {

nb::dict step_dict(const pipeline::MapperStep& step) {
  nb::dict d;
  d["frame"] = step.frame;
  d["pose"] = pose_array(step.pose);
  d["status"] = std::string(pipeline::to_string(step.status));
  d["keyframe"] = step.keyframe;
  d["poses_moved"] = step.poses_moved;
  d["evicted"] = step.evicted;
  d["fitness"] = step.fitness;
  d["seconds"] = step.seconds;
  return d;
}

// The metric-semantic grid (M2): classes and traversability weight per cell.
nb::dict semantic_dict(semantic::SemanticGrid grid) {
  nb::dict d;
  d["resolution"] = grid.resolution;
  d["origin"] = std::array<double, 2>{grid.origin.x(), grid.origin.y()};
  d["floor_z"] = grid.floor_z;
  d["classes"] = plane_array<std::uint8_t>(std::move(grid.classes));
  d["weight"] = plane_array<float>(std::move(grid.weight));
  d["objects"] = grid.objects.size();
  return d;
}

nb::dict result_dict(pipeline::MapPipelineResult result) {
  nb::dict d;
  d["poses"] = pose_stack(result.poses);
  d["map_from_slam"] = pose_array(result.map_from_slam);
  d["mesh"] = mesh_dict(result.mesh);
  d["band_occupancy"] = grid_dict(std::move(result.band_occupancy));
  d["occupancy"] = grid_dict(std::move(result.occupancy));
  d["rooms"] = plane_array<std::uint16_t>(std::move(result.rooms.rooms));
  d["room_count"] = result.rooms.records.size();
  d["semantic"] = semantic_dict(std::move(result.semantic));
  d["planes"] = result.planes.size();
  d["total_seconds"] = result.total_seconds();
  return d;
}

pipeline::Mapper make_mapper(const compute::Context& context, const PinholeIntrinsics& camera,
                             double depth_units, bool features, double voxel) {
  pipeline::MapperParams params;
  params.pipeline.features = features;
  params.volume.voxel_size = voxel;
  params.volume.truncation = 3 * voxel;  // the mapper's ratio (mapper_volume_params)
  return pipeline::Mapper(context, camera, depth_units, params);
}

}  // namespace

void bind_mapper(nb::module_& m) {
  nb::class_<pipeline::Mapper>(m, "Mapper")
      .def(
          "__init__",
          [](pipeline::Mapper* self, const compute::Context& context,
             const PinholeIntrinsics& camera, double depth_units, bool features, double voxel) {
            new (self) pipeline::Mapper(make_mapper(context, camera, depth_units, features, voxel));
          },
          nb::arg("context"), nb::arg("camera"), nb::arg("depth_units") = 1000.0,
          nb::arg("features") = true,
          nb::arg("voxel") = pipeline::mapper_volume_params().voxel_size, nb::keep_alive<1, 2>())
      .def(
          "add_frame",
          [](pipeline::Mapper& mapper, const DepthArray& depth,
             const std::optional<ColorArray>& color, const std::optional<PoseArray>& pose,
             const std::optional<PoseArray>& motion_prior) {
            registration::RgbdImages frame;
            frame.depth = borrow_depth(depth);
            frame.color = borrow_color(color);
            if (motion_prior) frame.motion_prior = to_pose(*motion_prior, "Mapper.add_frame");
            const auto given =
                pose ? std::optional(to_pose(*pose, "Mapper.add_frame")) : std::nullopt;
            return step_dict(mapper.add_frame(frame, given));
          },
          nb::arg("depth"), nb::arg("color") = nb::none(), nb::arg("pose") = nb::none(),
          nb::arg("motion_prior") = nb::none(),
          "Tracks (or takes the given camera-to-world pose of) the next frame and fuses it; "
          "motion_prior: another sensor's camera pose, which predicts the step")
      .def_prop_ro("poses",
                   [](const pipeline::Mapper& mapper) { return pose_stack(mapper.poses()); })
      .def("__len__", &pipeline::Mapper::frame_count)
      .def("mesh", [](pipeline::Mapper& mapper) { return mesh_dict(mapper.mesh()); })
      .def("distance_field",
           [](pipeline::Mapper& mapper) { return esdf_dict(mapper.distance_field()); })
      .def("occupancy", [](pipeline::Mapper& mapper) { return grid_dict(mapper.occupancy()); })
      .def("finish", [](pipeline::Mapper& mapper) { return result_dict(mapper.finish()); });
}

}  // namespace kartograf::python
