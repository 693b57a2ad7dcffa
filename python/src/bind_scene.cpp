// Planes of RGB-D frames (M1) and rooms of 2-D maps (M4).
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/rooms/room_methods.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/semantic/classify.hpp"
#include "map_dicts.hpp"

namespace kartograf::python {

namespace {

using CellArray = nb::ndarray<const std::uint8_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

std::array<double, 3> xyz(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

nb::dict plane_dict(const segmentation::Plane& p) {
  nb::dict d;
  d["id"] = p.id;
  d["normal"] = xyz(p.normal);
  d["offset"] = p.offset;
  d["centroid"] = xyz(p.centroid);
  d["inlier_count"] = p.inlier_count;
  d["rms_error"] = p.rms_error;
  return d;
}

// A depth array (depth_units per metre) as camera-frame points, on the context's device.
PointImage points_of(const compute::Context& context, const PinholeIntrinsics& camera,
                     const DepthArray& depth, double depth_units) {
  geometry::DepthRange range;
  range.units_per_metre = depth_units;
  return geometry::backproject(context, borrow_depth(depth), camera, range);
}

// The planes of one frame: depth (in depth_units per metre) back-projected, then extracted;
// without colour (None) in the cells mode only (PlaneExtractor::extract).
nb::dict extract_planes(const compute::Context& context, const PinholeIntrinsics& camera,
                        const DepthArray& depth, const std::optional<ColorArray>& color,
                        double depth_units, const std::string& mode) {
  require(mode == "regions" || mode == "cells",
          "planes: mode is 'regions' or 'cells', not '" + mode + "'");
  const PointImage points = points_of(context, camera, depth, depth_units);
  segmentation::PlaneExtractionParams params;
  params.mode = mode == "cells" ? segmentation::PlaneExtractionMode::cells
                                : segmentation::PlaneExtractionMode::regions;
  segmentation::PlaneExtractor extractor(context, camera, params);
  segmentation::PlaneSet set = extractor.extract(points, color ? borrow_color(*color) : RgbImage());
  nb::list planes;
  for (const segmentation::Plane& p : set.planes) planes.append(plane_dict(p));
  nb::dict d;
  d["planes"] = planes;
  d["labels"] = plane_array<std::uint16_t>(std::move(set.labels));
  d["milliseconds"] = set.timings.total();
  return d;
}

OccupancyGrid grid_of(const CellArray& cells, double resolution,
                      const std::array<double, 3>& origin) {
  OccupancyGrid grid;
  grid.resolution = resolution;
  grid.origin = {origin[0], origin[1], origin[2]};
  grid.cells = Image<CellState>(static_cast<int>(cells.shape(1)), static_cast<int>(cells.shape(0)));
  const std::uint8_t* values = cells.data();
  for (std::size_t i = 0; i < grid.cells.size(); ++i) {
    require(values[i] <= 2, "rooms: cell values are 0 (unknown), 1 (free) or 2 (occupied), not " +
                                std::to_string(values[i]));
    grid.cells.pixels()[i] = static_cast<CellState>(values[i]);
  }
  return grid;
}

nb::dict room_dict(const rooms::RoomRecord& r) {
  nb::dict d;
  d["id"] = r.id;
  d["area_m2"] = r.area_m2;
  d["centroid"] = std::array<double, 2>{r.centroid.x(), r.centroid.y()};
  d["neighbours"] = std::vector<int>(r.neighbours.begin(), r.neighbours.end());
  return d;
}

nb::dict segment(const compute::Context& context, const CellArray& cells, double resolution,
                 const std::array<double, 3>& origin, const std::string& method) {
  rooms::RoomSegmentation result = rooms::segment_rooms(context, grid_of(cells, resolution, origin),
                                                        rooms::parse_room_method(method));
  nb::list records;
  for (const rooms::RoomRecord& r : result.records) records.append(room_dict(r));
  nb::dict d;
  d["rooms"] = plane_array<std::uint16_t>(std::move(result.rooms));
  d["records"] = records;
  d["method"] = result.method;
  d["seconds"] = result.seconds;
  return d;
}

nb::dict evaluate(const DepthArray& ground_truth, const DepthArray& segmentation) {
  const eval::RoomSegmentationScores s =
      eval::evaluate_room_segmentation(borrow_labels(ground_truth), borrow_labels(segmentation));
  nb::dict d;
  d["recall"] = s.recall_mean;
  d["precision"] = s.precision_mean;
  d["mcc"] = s.mcc;
  d["ground_truth_rooms"] = s.ground_truth_rooms;
  d["segments"] = s.segments;
  return d;
}

// H x W x 4 float32 (x, y, z, 1; NaN where there is no point) as an organized point image. Copied:
// the library's points are 16-byte aligned Eigen vectors, an array's memory need not be.
using PointArray = nb::ndarray<const float, nb::shape<-1, -1, 4>, nb::c_contig, nb::device::cpu>;

PointImage copy_points(const PointArray& array) {
  PointImage points(static_cast<int>(array.shape(1)), static_cast<int>(array.shape(0)));
  const float* values = array.data();
  for (Point4f& p : points.pixels()) {
    p = std::isnan(values[0]) ? invalid_point() : Point4f(values[0], values[1], values[2], 1.0f);
    values += 4;
  }
  return points;
}

// M2 steps 1-3 on one organized view: per-pixel classes, regions and the up direction.
nb::dict label_points(const compute::Context& context, const PointArray& array) {
  const PointImage points = copy_points(array);
  semantic::SemanticLabelling labelling = semantic::label_organized_points(context, points);
  nb::dict d;
  d["classes"] = plane_array<std::uint8_t>(std::move(labelling.semantic));
  d["regions"] = plane_array<std::uint16_t>(std::move(labelling.regions.labels));
  d["region_count"] = labelling.regions.region_count;
  d["up"] = xyz(labelling.gravity.up);
  return d;
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const rooms::RoomMethod m : rooms::all_room_methods()) names.push_back(rooms::to_string(m));
  return names;
}

}  // namespace

void bind_scene(nb::module_& m) {
  m.def("extract_planes", &extract_planes, nb::arg("context"), nb::arg("camera"), nb::arg("depth"),
        nb::arg("color").none(), nb::arg("depth_units") = 1000.0, nb::arg("mode") = "regions");
  m.def(
      "read_map",
      [](const std::filesystem::path& path, double resolution) {
        const bool yaml = path.extension() == ".yaml" || path.extension() == ".yml";
        return grid_dict(yaml ? io::read_ros_map(path) : io::read_png_map(path, resolution));
      },
      nb::arg("path"), nb::arg("resolution") = 0.05,
      "A ROS map_server .yaml (with its image) or an ipa-style PNG (free white) as a grid");
  m.def("read_room_ground_truth", [](const std::filesystem::path& path) {
    return plane_array<std::uint16_t>(io::read_ground_truth_rooms(path));
  });
  m.def(
      "backproject",
      [](const compute::Context& context, const PinholeIntrinsics& camera, const DepthArray& depth,
         double depth_units) {
        PointImage points = points_of(context, camera, depth, depth_units);
        const auto w = std::size_t(points.width()), h = std::size_t(points.height());
        return image_array<float>(std::move(points), {h, w, 4});
      },
      nb::arg("context"), nb::arg("camera"), nb::arg("depth"), nb::arg("depth_units") = 1000.0);
  m.def("label_points", &label_points, nb::arg("context"), nb::arg("points"));
  m.def("read_semantic_png", [](const std::filesystem::path& path) {
    return plane_array<std::uint8_t>(io::read_semantic_png(path));
  });
  m.def("room_methods", &method_names);
  m.def("segment_rooms", &segment, nb::arg("context"), nb::arg("cells"), nb::arg("resolution"),
        nb::arg("origin"), nb::arg("method"));
  m.def("evaluate_rooms", &evaluate, nb::arg("ground_truth"), nb::arg("segmentation"));
}

}  // namespace kartograf::python
