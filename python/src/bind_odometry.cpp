#include <nanobind/stl/array.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <array>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/pipeline/mapper.hpp"
#include "kartograf/pipeline/tracking_choices.hpp"
#include "reports.hpp"
#include "sequence_handle.hpp"

namespace kartograf::python {

namespace {

// The odometry with the frames it tracks, fed one at a time from NumPy arrays.
class Odometry {
 public:
  Odometry(const compute::Context& context, const PinholeIntrinsics& camera, double depth_units,
           const pipeline::TrackingChoices& choices, double min_depth, double max_depth)
      : odometry_(context, camera, params(choices, depth_units, min_depth, max_depth)) {}

  // The depth array is read in place (no copy when it is C-contiguous uint16).
  nb::dict track(const DepthArray& depth, const std::optional<ColorArray>& color,
                 const std::optional<PoseArray>& motion_prior) {
    const DepthImage depth_image = borrow_depth(depth);
    const RgbImage color_image = borrow_color(color);
    last_depth_address_ = reinterpret_cast<std::uintptr_t>(depth_image.data());
    const auto prior =
        motion_prior ? std::optional(to_pose(*motion_prior, "Odometry.track")) : std::nullopt;
    const registration::OdometryFrame& frame =
        odometry_.track(depth_image, color ? &color_image : nullptr, prior);
    nb::dict d = frame_dict(frame);
    d["pose"] = pose_array(odometry_.poses().back());
    return d;
  }

  NumpyArray<double> poses() const { return pose_stack(odometry_.poses()); }
  std::size_t size() const { return odometry_.frame_count(); }
  std::uintptr_t last_depth_address() const { return last_depth_address_; }

 private:
  static registration::OdometryParams params(const pipeline::TrackingChoices& choices,
                                             double depth_units, double min_depth,
                                             double max_depth) {
    registration::OdometryParams p = pipeline::odometry_params(choices);
    p.depth_range = {depth_units, min_depth, max_depth};
    return p;
  }

  registration::RgbdOdometry odometry_;
  std::uintptr_t last_depth_address_ = 0;
};

pipeline::TrackingChoices choices(const std::string& method, int reestimate_every,
                                  const std::array<double, 3>& anchor_bounds,
                                  const std::string& tracking, double model_voxel) {
  return {method, reestimate_every, anchor_bounds, tracking, model_voxel};
}

nb::dict run_odometry(const compute::Context& context, const SequenceHandle& sequence,
                      const std::string& method, int reestimate_every,
                      const std::array<double, 3>& anchor_bounds, const std::string& tracking,
                      double model_voxel) {
  const pipeline::TrackingChoices c =
      choices(method, reestimate_every, anchor_bounds, tracking, model_voxel);
  const auto source = sequence.source();
  mapping::OdometryRun run;
  {
    nb::gil_scoped_release unlocked;  // other Python threads go on meanwhile
    run = mapping::run_odometry(context, *source, pipeline::odometry_params(c), {},
                                pipeline::model_tracking_params(c));
  }
  nb::dict d = odometry_run_dict(run);
  d["ground_truth"] = optional_poses(source->ground_truth());
  return d;
}

}  // namespace

// The defaults the package's Python signatures show, from the C++ ones.
nb::dict tracking_defaults() {
  const pipeline::TrackingChoices defaults;
  nb::dict d;
  d["method"] = defaults.method;
  d["reestimate_every"] = defaults.reestimate_interval;
  d["anchor_bounds"] = nb::make_tuple(defaults.anchor_bounds[0], defaults.anchor_bounds[1],
                                      defaults.anchor_bounds[2]);
  d["tracking"] = defaults.tracking;
  d["model_voxel"] = defaults.model_voxel;
  d["min_depth"] = geometry::DepthRange{}.min_metres;
  d["max_depth"] = geometry::DepthRange{}.max_metres;
  d["map_voxel"] = mapping::MapFusionParams{}.voxel_size;
  d["mapper_voxel"] = pipeline::mapper_volume_params().voxel_size;
  return d;
}

void bind_odometry(nb::module_& m) {
  m.def("tracking_defaults", &tracking_defaults);
  const pipeline::TrackingChoices defaults;
  nb::class_<Odometry>(m, "Odometry")
      .def(
          "__init__",
          [](Odometry* self, const compute::Context& context, const PinholeIntrinsics& camera,
             double depth_units, const std::string& method, int reestimate_every,
             const std::array<double, 3>& anchor_bounds, double min_depth, double max_depth) {
            new (self) Odometry(context, camera, depth_units,
                                choices(method, reestimate_every, anchor_bounds, "frame", 0.02),
                                min_depth, max_depth);
          },
          nb::arg("context"), nb::arg("camera"), nb::arg("depth_units") = 1000.0,
          nb::arg("method") = defaults.method,
          nb::arg("reestimate_every") = defaults.reestimate_interval,
          nb::arg("anchor_bounds") = defaults.anchor_bounds,
          nb::arg("min_depth") = geometry::DepthRange{}.min_metres,
          nb::arg("max_depth") = geometry::DepthRange{}.max_metres, nb::keep_alive<1, 2>())
      .def("track", &Odometry::track, nb::arg("depth"), nb::arg("color") = nb::none(),
           nb::arg("motion_prior") = nb::none(),
           "Registers the next frame (motion_prior: another sensor's camera-to-world pose, which "
           "predicts the step with the previous frame's); returns its report with its pose")
      .def_prop_ro("poses", &Odometry::poses, nb::rv_policy::move)
      .def("__len__", &Odometry::size)
      .def_prop_ro("last_depth_address", &Odometry::last_depth_address,
                   "Where the last depth image was read from (the array's own memory)");
  m.def("run_odometry", &run_odometry, nb::arg("context"), nb::arg("sequence"),
        nb::arg("method") = defaults.method,
        nb::arg("reestimate_every") = defaults.reestimate_interval,
        nb::arg("anchor_bounds") = defaults.anchor_bounds, nb::arg("tracking") = defaults.tracking,
        nb::arg("model_voxel") = defaults.model_voxel);
}

}  // namespace kartograf::python
