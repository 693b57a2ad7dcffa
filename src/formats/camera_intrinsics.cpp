#include "kartograf/formats/camera_intrinsics.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <system_error>
#include <utility>

#include "formats/atomic_file.hpp"
#include "formats/input_file.hpp"
#include "formats/text_fields.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/sequence.hpp"

namespace kartograf::io {

namespace {

using detail::quoted;

// Published intrinsics at 640x480: TUM's "Calibration of the Kinect" page (fr1, fr2, fr3 and the
// default 525 camera) and Microsoft 7-Scenes.
const std::vector<std::pair<std::string, PinholeIntrinsics>>& presets() {
  static const std::vector<std::pair<std::string, PinholeIntrinsics>> table = {
      {"tum-fr1", {640, 480, 517.3, 516.5, 318.6, 255.3}},
      {"tum-fr2", {640, 480, 520.9, 521.0, 325.1, 249.7}},
      {"tum-fr3", {640, 480, 535.4, 539.2, 320.1, 247.6}},
      {"kinect", {640, 480, 525.0, 525.0, 319.5, 239.5}},
      {"7scenes", {640, 480, 585.0, 585.0, 320.0, 240.0}},
  };
  return table;
}

// "fx,fy,cx,cy" as four finite numbers; empty when the value has another form.
std::optional<PinholeIntrinsics> four_numbers(const std::string& value) {
  const std::vector<std::string_view> fields = detail::split_fields(value, ",");
  if (fields.size() != 4 || std::count(value.begin(), value.end(), ',') != 3) return std::nullopt;
  double v[4];
  for (int i = 0; i < 4; ++i) {
    const auto number = detail::parse_number<double>(fields[static_cast<std::size_t>(i)]);
    if (!number || !std::isfinite(*number)) return std::nullopt;
    v[i] = *number;
  }
  return PinholeIntrinsics{0, 0, v[0], v[1], v[2], v[3]};
}

// Focal lengths and principal point only (the size may still be unknown).
void validate_without_size(const PinholeIntrinsics& k, const std::string& what) {
  PinholeIntrinsics sized = k;
  sized.width = std::max(k.width, 1);
  sized.height = std::max(k.height, 1);
  sized.validate(what);
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

std::optional<PinholeIntrinsics> camera_preset(std::string_view name) {
  for (const auto& [preset, k] : presets()) {
    if (preset == name) return k;
  }
  return std::nullopt;
}

const std::vector<std::string>& camera_preset_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> list;
    for (const auto& entry : presets()) list.push_back(entry.first);
    return list;
  }();
  return names;
}

PinholeIntrinsics read_camera_matrix_txt(const std::filesystem::path& path) {
  std::ifstream in = detail::open_text_file(path);
  double m[9];
  for (int k = 0; k < 9; ++k) {
    require(static_cast<bool>(in >> m[k]) && std::isfinite(m[k]),
            quoted(path) + ": expected the 3x3 camera matrix K as 9 numbers, number " +
                std::to_string(k + 1) + " is missing or not finite");
  }
  require(m[1] == 0 && m[3] == 0 && m[6] == 0 && m[7] == 0 && m[8] == 1,
          quoted(path) +
              ": not a pinhole camera matrix [fx 0 cx; 0 fy cy; 0 0 1] (skew, or a "
              "last row other than 0 0 1)");
  const PinholeIntrinsics k{0, 0, m[0], m[4], m[2], m[5]};
  validate_without_size(k, quoted(path));
  return k;
}

Camera parse_camera_argument(const std::string& value) {
  if (const auto preset = camera_preset(value)) return {*preset, "preset", "preset " + value};
  if (const auto k = four_numbers(value)) {
    validate_without_size(*k, "--camera " + value);
    return {*k, "option", "--camera " + value};
  }
  const std::filesystem::path path(value);
  std::error_code unreadable;  // e.g. a name too long for a path: not a file, not an exception
  if (std::filesystem::is_regular_file(path, unreadable)) {
    const bool json = path.extension() == ".json";
    return {json ? read_camera_intrinsics_json(path) : read_camera_matrix_txt(path), "file",
            "file " + quoted(path)};
  }
  std::string names;
  for (const std::string& name : camera_preset_names()) names += (names.empty() ? "" : "|") + name;
  throw Error("--camera '" + value + "': not a preset (" + names +
              "), not 'fx,fy,cx,cy' (four numbers) and no such file (camera-intrinsics.txt with "
              "a 3x3 matrix, or Open3D's camera_intrinsics.json)");
}

std::optional<std::string> tum_preset_of_folder(const std::filesystem::path& folder) {
  std::string name = std::filesystem::absolute(folder).lexically_normal().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::size_t at = name.rfind("freiburg");
  if (at == std::string::npos || at + 8 >= name.size()) return std::nullopt;
  const char camera = name[at + 8];
  if (camera < '1' || camera > '3') return std::nullopt;
  return std::string("tum-fr") + camera;
}

Camera fit_camera_to_frames(Camera camera, int width, int height) {
  PinholeIntrinsics& k = camera.intrinsics;
  if (k.width == 0 && k.height == 0) {
    k.width = width;
    k.height = height;
  } else if (k.width != width || k.height != height) {
    require(camera.source == "preset" || camera.source == "default",
            "camera " + camera.description + " is for " + size_text(k.width, k.height) +
                " images, the frames are " + size_text(width, height));
    // A preset is for 640x480: a resized sequence keeps its field of view.
    const double sx = static_cast<double>(width) / k.width;
    const double sy = static_cast<double>(height) / k.height;
    camera.description += " scaled from " + size_text(k.width, k.height);
    k = {width, height, k.fx * sx, k.fy * sy, k.cx * sx, k.cy * sy};
  }
  k.validate("camera " + camera.description);
  return camera;
}

std::string describe(const Camera& camera) {
  const PinholeIntrinsics& k = camera.intrinsics;
  char text[160];
  std::snprintf(text, sizeof(text), "fx %.6g fy %.6g cx %.6g cy %.6g (%dx%d, ", k.fx, k.fy, k.cx,
                k.cy, k.width, k.height);
  return text + camera.description + ")";
}

}  // namespace kartograf::io
