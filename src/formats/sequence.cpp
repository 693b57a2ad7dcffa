#include "kartograf/formats/sequence.hpp"

#include <Eigen/SVD>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/atomic_file.hpp"
#include "formats/input_file.hpp"
#include "formats/listed_sequence.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/tum.hpp"

namespace kartograf::io {

namespace {

using detail::quoted;

// Reads `count` whitespace-separated finite numbers; throws naming the file.
std::vector<double> read_numbers(const std::filesystem::path& path, std::size_t count) {
  std::ifstream in = detail::open_text_file(path);
  std::vector<double> values(count);
  for (std::size_t k = 0; k < count; ++k) {
    require(static_cast<bool>(in >> values[k]) && std::isfinite(values[k]),
            quoted(path) + ": expected " + std::to_string(count) + " numbers, number " +
                std::to_string(k + 1) + " is missing or not finite");
  }
  return values;
}

template <class Pixel>
std::string size_text(const Image<Pixel>& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height());
}

Eigen::Matrix4d matrix_from(const std::vector<double>& values, std::size_t offset) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = values[offset + 4 * r + c];
  }
  return m;
}

}  // namespace

Eigen::Isometry3d rotation_pose(const Eigen::Matrix4d& matrix, const std::string& where) {
  require(matrix.allFinite(), where + ": the pose matrix has a value that is not finite");
  const Eigen::Matrix3d r = matrix.topLeftCorner<3, 3>();
  const double off = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
  const double det = r.determinant();
  char numbers[160];
  std::snprintf(numbers, sizeof(numbers),
                "||R^T R - I|| = %.3g, det(R) = %.3g; accepted: ||R^T R - I|| under %g, det > 0",
                off, det, kPoseRotationTolerance);
  require(off < kPoseRotationTolerance && det > 0,
          where + ": the pose's 3x3 block is not a rotation (" + numbers + ")");
  const Eigen::RowVector4d last = matrix.row(3);
  require((last - Eigen::RowVector4d(0, 0, 0, 1)).norm() < 1e-6,
          where + ": the pose matrix's last row is not 0 0 0 1");
  return orthonormalized_pose(matrix);
}

namespace detail {

namespace {

// The frame with its ground-truth pose, from the list or its pose file.
RgbdFrame with_pose(const FrameFiles& files, RgbdFrame frame) {
  frame.pose = files.pose;
  if (!files.pose_file.empty()) {
    frame.pose =
        rotation_pose(matrix_from(read_numbers(files.pose_file, 16), 0), quoted(files.pose_file));
  }
  return frame;
}

}  // namespace

ListedSequence::ListedSequence(std::vector<FrameFiles> frames, const PinholeIntrinsics& camera,
                               double depth_units_per_metre)
    : frames_(std::move(frames)), camera_(camera), depth_units_per_metre_(depth_units_per_metre) {
  camera_.validate("sequence camera");
  require(std::isfinite(depth_units_per_metre) && depth_units_per_metre > 0,
          "depth scale must be a positive number of units per metre, got " +
              std::to_string(depth_units_per_metre));
}

RgbdFrame ListedSequence::frame(std::size_t i) const {
  require(i < frames_.size(), "sequence frame " + std::to_string(i) +
                                  " requested, the sequence has " + std::to_string(frames_.size()));
  const FrameFiles& files = frames_[i];
  require(files.missing.empty(), quoted(files.missing) + ": no such file (frame " +
                                     std::to_string(i) + " of the sequence)");
  RgbdFrame frame;
  frame.index = files.position;
  frame.timestamp = files.timestamp;
  frame.color_file = files.color;
  frame.depth_file = files.depth;
  frame.depth = read_depth_png(files.depth);
  require(frame.depth.width() == camera_.width && frame.depth.height() == camera_.height,
          "depth image " + quoted(files.depth) + " is " + size_text(frame.depth) +
              ", the sequence's frames are " + std::to_string(camera_.width) + "x" +
              std::to_string(camera_.height));
  if (files.color.empty()) return with_pose(files, std::move(frame));  // a depth camera alone
  frame.color = read_color_image(files.color);
  require(
      frame.color.width() == frame.depth.width() && frame.color.height() == frame.depth.height(),
      "colour image " + quoted(files.color) + " is " + size_text(frame.color) +
          ", its depth image " + quoted(files.depth) + " is " + size_text(frame.depth) +
          " (colour must be on the depth image's pixel grid)");
  return with_pose(files, std::move(frame));
}

}  // namespace detail

PinholeIntrinsics read_camera_intrinsics_json(const std::filesystem::path& path) {
  std::ifstream in = detail::open_text_file(path);
  nlohmann::json json;
  try {
    in >> json;
  } catch (const nlohmann::json::exception& e) {
    throw Error(quoted(path) + ": not valid JSON: " + e.what());
  }
  auto field = [&](const char* name) -> const nlohmann::json& {
    require(json.is_object() && json.contains(name),
            quoted(path) + ": missing field '" + name + "'");
    return json.at(name);
  };
  auto number = [&](const nlohmann::json& value, const std::string& what) {
    require(value.is_number() && std::isfinite(value.get<double>()),
            quoted(path) + ": field '" + what + "' must be a finite number");
    return value.get<double>();
  };
  auto integer = [&](const char* name) {
    const nlohmann::json& value = field(name);
    require(value.is_number_integer() && value.get<long long>() > 0 &&
                value.get<long long>() <= 1 << 20,
            quoted(path) + ": field '" + name + "' must be a positive integer");
    return static_cast<int>(value.get<long long>());
  };
  const nlohmann::json& matrix = field("intrinsic_matrix");
  require(
      matrix.is_array() && matrix.size() == 9,
      quoted(path) + ": field 'intrinsic_matrix' must be an array of 9 numbers (column-major 3x3)");
  double m[9];
  for (int i = 0; i < 9; ++i)
    m[i] = number(matrix[i], "intrinsic_matrix[" + std::to_string(i) + "]");
  PinholeIntrinsics k;
  k.width = integer("width");
  k.height = integer("height");
  k.fx = m[0];
  k.fy = m[4];
  k.cx = m[6];
  k.cy = m[7];
  require(m[1] == 0 && m[2] == 0 && m[3] == 0 && m[5] == 0 && m[8] == 1,
          quoted(path) +
              ": field 'intrinsic_matrix' is not a pinhole matrix [fx 0 0 0 fy 0 cx cy 1] "
              "(skew or a non-unit last element)");
  k.validate(quoted(path));
  return k;
}

void write_camera_intrinsics_json(const std::filesystem::path& path, const PinholeIntrinsics& k) {
  k.validate("camera intrinsics for " + quoted(path));
  nlohmann::ordered_json json;
  json["width"] = k.width;
  json["height"] = k.height;
  json["intrinsic_matrix"] = {k.fx, 0.0, 0.0, 0.0, k.fy, 0.0, k.cx, k.cy, 1.0};
  const std::string text = json.dump(4) + "\n";
  detail::write_file_atomically(path, text.data(), text.size());
}

std::unique_ptr<Sequence> open_tum_sequence(const std::filesystem::path& folder,
                                            double max_difference,
                                            std::optional<PinholeIntrinsics> intrinsics) {
  detail::FrameList list = detail::list_tum_frames(folder, max_difference);
  if (intrinsics) list.camera = {*intrinsics, "option", "given"};
  return detail::open_listed(std::move(list), {}).sequence;
}

std::unique_ptr<Sequence> open_seven_scenes(const std::filesystem::path& folder) {
  return detail::open_listed(detail::list_numbered_frames(folder), {}).sequence;
}

Trajectory read_redwood_log(const std::filesystem::path& path) {
  std::ifstream in = detail::open_text_file(path);
  Trajectory trajectory;
  std::string line;
  std::size_t line_number = 0;
  auto next_line = [&]() -> bool {
    while (std::getline(in, line)) {
      ++line_number;
      if (line.find_first_not_of(" \t\r") != std::string::npos) return true;
    }
    return false;
  };
  while (next_line()) {
    long long ids[3];
    require(std::sscanf(line.c_str(), "%lld %lld %lld", &ids[0], &ids[1], &ids[2]) == 3,
            quoted(path) + " line " + std::to_string(line_number) + ": expected 'i j k' frame ids");
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      require(next_line(), quoted(path) + ": truncated after line " + std::to_string(line_number) +
                               " (a 4x4 matrix needs 4 rows)");
      double v[4];
      require(
          std::sscanf(line.c_str(), "%lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3]) == 4 &&
              std::isfinite(v[0] + v[1] + v[2] + v[3]),
          quoted(path) + " line " + std::to_string(line_number) + ": expected 4 finite numbers");
      for (int c = 0; c < 4; ++c) m(r, c) = v[c];
    }
    StampedPose pose;
    pose.timestamp = static_cast<double>(trajectory.size());
    pose.pose =
        rotation_pose(m, quoted(path) + " matrix at lines " + std::to_string(line_number - 3) +
                             "-" + std::to_string(line_number));
    trajectory.push_back(pose);
  }
  return trajectory;
}

}  // namespace kartograf::io
