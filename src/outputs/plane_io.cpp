#include "kartograf/outputs/plane_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.hpp"
#include "formats/input_file.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "outputs/json_array.hpp"

namespace kartograf::io {

namespace {

using Json = nlohmann::ordered_json;

using detail::json_array;

Json plane_json(const segmentation::Plane& plane) {
  return {{"id", plane.id},
          {"normal", json_array(plane.normal)},
          {"offset", plane.offset},
          {"centroid", json_array(plane.centroid)},
          {"major_axis", json_array(plane.major_axis)},
          {"minor_axis", json_array(plane.minor_axis)},
          {"extent_min", json_array(plane.extent_min)},
          {"extent_max", json_array(plane.extent_max)},
          {"inlier_count", plane.inlier_count},
          {"rms_error", plane.rms_error}};
}

// A fixed-size vector field of a plane object; throws naming the file, plane and field.
template <int N>
Eigen::Matrix<double, N, 1> vector_field(const Json& plane, const char* field,
                                         const std::string& where) {
  const auto it = plane.find(field);
  if (it == plane.end() || !it->is_array() || it->size() != N) {
    throw Error(where + ": \"" + field + "\" must be an array of " + std::to_string(N) +
                " numbers");
  }
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) {
    if (!(*it)[i].is_number()) throw Error(where + ": \"" + field + "\" holds a non-number");
    v[i] = (*it)[i].get<double>();
  }
  return v;
}

double number_field(const Json& object, const char* field, const std::string& where) {
  const auto it = object.find(field);
  if (it == object.end() || !it->is_number()) {
    throw Error(where + ": \"" + field + "\" must be a number");
  }
  return it->get<double>();
}

}  // namespace

void write_planes_json(const std::filesystem::path& path, const segmentation::PlaneSet& planes,
                       const PlaneFileInfo& info) {
  Json json;
  json["format"] = "kartograf-planes";
  json["version"] = 1;
  json["source"] = info.source;
  json["width"] = planes.labels.width();
  json["height"] = planes.labels.height();
  json["intrinsics"] = {{"fx", info.intrinsics.fx},
                        {"fy", info.intrinsics.fy},
                        {"cx", info.intrinsics.cx},
                        {"cy", info.intrinsics.cy}};
  json["segment_count"] = planes.segment_count;
  json["merged_count"] = planes.merged_count;
  const segmentation::PlaneExtractionTimings& t = planes.timings;
  json["timings_ms"] = {
      {"lab", t.lab},         {"growing", t.growing},       {"moments", t.moments},
      {"merging", t.merging}, {"refinement", t.refinement}, {"output", t.output},
      {"total", t.total()}};
  if (!info.run_json.empty()) json["run"] = Json::parse(info.run_json);
  Json list = Json::array();
  for (const segmentation::Plane& plane : planes.planes) list.push_back(plane_json(plane));
  json["planes"] = std::move(list);
  const std::string text = json.dump(1) + "\n";
  detail::write_file_atomically(path, text.data(), text.size());
}

std::vector<segmentation::Plane> read_planes_json(const std::filesystem::path& path) {
  const std::string name = "planes file " + detail::quoted(path);
  const std::vector<std::uint8_t> bytes = detail::read_file_bytes(path, name);
  Json json;
  try {
    json = Json::parse(bytes.begin(), bytes.end());
  } catch (const nlohmann::json::exception& e) {
    throw Error(name + ": not valid JSON (" + e.what() + ")");
  }
  if (!json.is_object() || json.value("format", "") != "kartograf-planes") {
    throw Error(name + ": not a kartograf planes file (\"format\" is not \"kartograf-planes\")");
  }
  const auto list = json.find("planes");
  if (list == json.end() || !list->is_array()) throw Error(name + ": no \"planes\" array");
  std::vector<segmentation::Plane> planes;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const Json& p = (*list)[i];
    const std::string where = name + ", plane " + std::to_string(i);
    if (!p.is_object()) throw Error(where + ": not an object");
    segmentation::Plane plane;
    const double id = number_field(p, "id", where);
    if (id < 1 || id > 65535 || id != static_cast<double>(static_cast<Label>(id))) {
      throw Error(where + ": \"id\" must be an integer in 1..65535");
    }
    plane.id = static_cast<Label>(id);
    plane.normal = vector_field<3>(p, "normal", where);
    if (!(std::abs(plane.normal.norm() - 1.0) < 1e-6)) {
      throw Error(where + ": \"normal\" is not of unit length");
    }
    plane.offset = number_field(p, "offset", where);
    plane.centroid = vector_field<3>(p, "centroid", where);
    plane.major_axis = vector_field<3>(p, "major_axis", where);
    plane.minor_axis = vector_field<3>(p, "minor_axis", where);
    plane.extent_min = vector_field<2>(p, "extent_min", where);
    plane.extent_max = vector_field<2>(p, "extent_max", where);
    const double count = number_field(p, "inlier_count", where);
    if (count < 0) throw Error(where + ": \"inlier_count\" is negative");
    plane.inlier_count = static_cast<std::uint64_t>(count);
    plane.rms_error = number_field(p, "rms_error", where);
    planes.push_back(plane);
  }
  return planes;
}

RgbImage depth_shading(const PointImage& points) {
  float nearest = std::numeric_limits<float>::infinity(), farthest = 0.0f;
  for (const Point4f& p : points.pixels()) {
    if (!is_valid(p)) continue;
    nearest = std::min(nearest, p.z());
    farthest = std::max(farthest, p.z());
  }
  RgbImage out(points.width(), points.height(), Rgb8{0, 0, 0});
  const float range = std::max(farthest - nearest, 1e-3f);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point4f& p = points.data()[i];
    if (!is_valid(p)) continue;
    const auto grey =
        static_cast<std::uint8_t>(std::lround(230.0f - 180.0f * (p.z() - nearest) / range));
    out.data()[i] = {grey, grey, grey};
  }
  return out;
}

RgbImage plane_overlay(const RgbImage& rgb, const LabelImage& labels) {
  require(rgb.width() == labels.width() && rgb.height() == labels.height(),
          "plane overlay: colour image and labels differ in size");
  const RgbImage colours = colorize_labels(labels);
  RgbImage out(rgb.width(), rgb.height());
  for (int y = 0; y < rgb.height(); ++y) {
    for (int x = 0; x < rgb.width(); ++x) {
      const Rgb8& c = rgb(x, y);
      const int grey = (c[0] * 77 + c[1] * 150 + c[2] * 29) >> 8;
      const int dimmed = 40 + grey / 3;
      const Label l = labels(x, y);
      if (l == kUnlabeled) {
        out(x, y) = {static_cast<std::uint8_t>(dimmed), static_cast<std::uint8_t>(dimmed),
                     static_cast<std::uint8_t>(dimmed)};
        continue;
      }
      const bool border = (x + 1 < rgb.width() && labels(x + 1, y) != l) ||
                          (y + 1 < rgb.height() && labels(x, y + 1) != l);
      const Rgb8& p = colours(x, y);
      for (int k = 0; k < 3; ++k) {
        const int blended = border ? p[k] / 3 : (p[k] * 3 + dimmed) / 4;
        out(x, y)[k] = static_cast<std::uint8_t>(blended);
      }
    }
  }
  return out;
}

PointCloud plane_points(const PointImage& points, const LabelImage& labels) {
  require(points.width() == labels.width() && points.height() == labels.height(),
          "plane points: point image and labels differ in size");
  const RgbImage colours = colorize_labels(labels);
  PointCloud cloud;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (labels.data()[i] == kUnlabeled || !is_valid(points.data()[i])) continue;
    cloud.points.push_back(points.data()[i].head<3>());
    cloud.colors.push_back(colours.data()[i]);
  }
  return cloud;
}

}  // namespace kartograf::io
