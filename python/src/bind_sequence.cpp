#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <filesystem>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"
#include "sequence_handle.hpp"

namespace kartograf::python {

namespace {

SequenceHandle open(const std::filesystem::path& folder, const std::string& camera,
                    std::optional<double> depth_scale, std::size_t first,
                    std::optional<std::size_t> frames, std::size_t step, bool skip_bad_frames) {
  io::SequenceParams params;
  params.camera = camera;
  params.depth_units_per_metre = depth_scale;
  params.first = first;
  params.count = frames;
  params.step = step;
  params.skip_bad_frames = skip_bad_frames;
  return {io::open_sequence(folder, params)};
}

nb::dict frame_dict(const SequenceHandle& s, std::size_t i) {
  require(i < s.opened.sequence->size(), "sequence: frame " + std::to_string(i) +
                                             " of a sequence of " +
                                             std::to_string(s.opened.sequence->size()));
  io::RgbdFrame frame = s.opened.sequence->frame(i);
  nb::dict d;
  d["index"] = frame.index;
  d["timestamp"] = frame.timestamp;
  d["depth"] = depth_array(std::move(frame.depth));
  d["color"] = frame.color.empty() ? nb::none() : nb::cast(color_array(std::move(frame.color)));
  d["pose"] = frame.pose ? nb::cast(pose_array(*frame.pose)) : nb::none();
  return d;
}

nb::dict synthesize(const std::filesystem::path& folder, std::uint64_t seed, int frames,
                    const std::string& trajectory, bool noise, bool survey, int width, int height,
                    bool force, int threads) {
  require(trajectory == "robot" || trajectory == "handheld",
          "synthesize: trajectory must be 'robot' or 'handheld', not '" + trajectory + "'");
  io::SyntheticDatasetParams params;
  params.seed = seed;
  params.frames = frames;
  params.trajectory =
      trajectory == "handheld" ? io::SyntheticTrajectory::handheld : io::SyntheticTrajectory::robot;
  params.tour.survey = survey;
  // The CLI's default camera: the Kinect's 525 px at 640 wide, scaled; centred.
  params.intrinsics = {width,
                       height,
                       525.0 * width / 640.0,
                       525.0 * width / 640.0,
                       (width - 1) / 2.0,
                       (height - 1) / 2.0};
  params.noise = noise ? synth::NoiseModel::kinect() : synth::NoiseModel::none();
  params.force = force;
  params.threads = threads;
  const io::SyntheticDatasetSummary summary = io::write_synthetic_dataset(folder, params);
  std::vector<Eigen::Isometry3d> poses;
  for (const StampedPose& p : summary.trajectory) poses.push_back(p.pose);
  nb::dict d;
  d["frames"] = summary.trajectory.size();
  d["files"] = summary.files;
  d["rooms"] = summary.world.rooms.size();
  d["poses"] = pose_stack(poses);
  return d;
}

// Image files as the library reads and writes them (the bag converter uses them).
void bind_image_files(nb::module_& m) {
  m.def("read_depth_png",
        [](const std::filesystem::path& path) { return depth_array(io::read_depth_png(path)); });
  m.def("read_color_image",
        [](const std::filesystem::path& path) { return color_array(io::read_color_image(path)); });
  m.def("write_depth_png", [](const std::filesystem::path& path, const DepthArray& depth) {
    io::write_png(path, borrow_depth(depth));
  });
  m.def("write_color_png", [](const std::filesystem::path& path, const ColorArray& color) {
    io::write_png(path, borrow_color(color));
  });
  m.def("write_camera_intrinsics_json", &io::write_camera_intrinsics_json, nb::arg("path"),
        nb::arg("camera"));
}

}  // namespace

void bind_sequence(nb::module_& m) {
  bind_image_files(m);
  nb::class_<SequenceHandle>(m, "Sequence")
      .def("__len__", [](const SequenceHandle& s) { return s.opened.sequence->size(); })
      .def_prop_ro("camera",
                   [](const SequenceHandle& s) { return s.opened.sequence->intrinsics(); })
      .def_prop_ro(
          "depth_units_per_metre",
          [](const SequenceHandle& s) { return s.opened.sequence->depth_units_per_metre(); })
      .def_prop_ro("layout",
                   [](const SequenceHandle& s) {
                     return std::string(io::to_string(s.opened.detected.layout));
                   })
      .def_prop_ro("warnings", [](const SequenceHandle& s) { return s.opened.warnings; })
      .def_prop_ro(
          "has_color", [](const SequenceHandle& s) { return s.opened.has_color; },
          "False for a depth camera alone (every frame's color is None)")
      .def_prop_ro("description",
                   [](const SequenceHandle& s) { return io::describe_input(s.opened); })
      .def("frame", &frame_dict, nb::arg("i"),
           "Frame i: dict(index, timestamp, depth (H x W uint16), color (H x W x 3 uint8 or "
           "None), pose (4 x 4 camera-to-world ground truth or None))");
  m.def("open_sequence", &open, nb::arg("folder"), nb::arg("camera") = "",
        nb::arg("depth_scale") = nb::none(), nb::arg("first") = 0, nb::arg("frames") = nb::none(),
        nb::arg("step") = 1, nb::arg("skip_bad_frames") = false);
  m.def("synthesize", &synthesize, nb::arg("folder"), nb::arg("seed") = 1, nb::arg("frames") = 300,
        nb::arg("trajectory") = "robot", nb::arg("noise") = true, nb::arg("survey") = false,
        nb::arg("width") = 640, nb::arg("height") = 480, nb::arg("force") = false,
        nb::arg("threads") = 0, "Writes a synthetic data set (as `kartograf synth`) into folder");
}

}  // namespace kartograf::python
