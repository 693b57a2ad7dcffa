#include "kartograf/io/sequence.hpp"

#include <Eigen/SVD>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"
#include "io/input_file.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/io/image_io.hpp"
#include "kartograf/io/tum.hpp"

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

Eigen::Matrix4d matrix_from(const std::vector<double>& values, std::size_t offset) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = values[offset + 4 * r + c];
  }
  return m;
}

class TumSequence final : public Sequence {
 public:
  TumSequence(const std::filesystem::path& folder, double max_difference, const PinholeIntrinsics& intrinsics)
      : folder_(folder), intrinsics_(intrinsics) {
    const auto rgb = read_tum_file_list(folder / "rgb.txt");
    const auto depth = read_tum_file_list(folder / "depth.txt");
    std::vector<double> rgb_times, depth_times;
    for (const auto& f : rgb) rgb_times.push_back(f.timestamp);
    for (const auto& f : depth) depth_times.push_back(f.timestamp);
    Trajectory ground_truth;
    std::vector<double> gt_times;
    if (std::filesystem::exists(folder / "groundtruth.txt")) {
      ground_truth = read_tum_trajectory(folder / "groundtruth.txt");
      for (const auto& p : ground_truth) gt_times.push_back(p.timestamp);
    }
    for (const auto& [i, j] : associate_timestamps(rgb_times, depth_times, max_difference)) {
      Entry entry{depth_times[j], rgb[i].file, depth[j].file, std::nullopt};
      entries_.push_back(entry);
    }
    std::vector<double> frame_times;
    for (const Entry& e : entries_) frame_times.push_back(e.timestamp);
    for (const auto& [f, g] : associate_timestamps(frame_times, gt_times, max_difference)) {
      entries_[f].pose = ground_truth[g].pose;
    }
    require(!entries_.empty(), quoted(folder) + ": no rgb/depth pair within " + std::to_string(max_difference) +
                                   " s (empty or mismatched rgb.txt / depth.txt)");
  }

  std::size_t size() const override { return entries_.size(); }
  PinholeIntrinsics intrinsics() const override { return intrinsics_; }
  double depth_units_per_metre() const override { return 5000.0; }

  RgbdFrame frame(std::size_t i) const override {
    const Entry& e = entries_.at(i);
    RgbdFrame frame;
    frame.index = i;
    frame.timestamp = e.timestamp;
    frame.color = read_color_image(folder_ / e.color);
    frame.depth = read_depth_png(folder_ / e.depth);
    frame.pose = e.pose;
    return frame;
  }

 private:
  struct Entry {
    double timestamp;
    std::string color, depth;
    std::optional<Eigen::Isometry3d> pose;
  };
  std::filesystem::path folder_;
  PinholeIntrinsics intrinsics_;
  std::vector<Entry> entries_;
};

class SevenScenesSequence final : public Sequence {
 public:
  explicit SevenScenesSequence(const std::filesystem::path& folder) {
    frames_ = std::filesystem::is_directory(folder / "frames") ? folder / "frames" : folder;
    intrinsics_ = PinholeIntrinsics::kinect_7scenes();
    if (std::filesystem::exists(folder / "camera-intrinsics.txt")) {
      const auto k = read_numbers(folder / "camera-intrinsics.txt", 9);
      intrinsics_.fx = k[0];
      intrinsics_.cx = k[2];
      intrinsics_.fy = k[4];
      intrinsics_.cy = k[5];
      intrinsics_.validate(quoted(folder / "camera-intrinsics.txt"));
    }
    while (std::filesystem::exists(path(count_, ".depth.png"))) ++count_;
    require(count_ > 0, quoted(frames_) + ": no frame-000000.depth.png (not a 7-Scenes folder)");
  }

  std::size_t size() const override { return count_; }
  PinholeIntrinsics intrinsics() const override { return intrinsics_; }
  double depth_units_per_metre() const override { return 1000.0; }

  RgbdFrame frame(std::size_t i) const override {
    require(i < count_, "7-Scenes frame " + std::to_string(i) + " requested, the sequence has " +
                            std::to_string(count_));
    RgbdFrame frame;
    frame.index = i;
    frame.timestamp = static_cast<double>(i) / 30.0;
    frame.color = read_color_image(path(i, ".color.jpg"));
    frame.depth = read_depth_png(path(i, ".depth.png"));
    if (std::filesystem::exists(path(i, ".pose.txt"))) {
      frame.pose = orthonormalized_pose(matrix_from(read_numbers(path(i, ".pose.txt"), 16), 0));
    }
    return frame;
  }

 private:
  std::filesystem::path path(std::size_t i, const char* suffix) const {
    char name[64];
    std::snprintf(name, sizeof(name), "frame-%06zu%s", i, suffix);
    return frames_ / name;
  }

  std::filesystem::path frames_;
  PinholeIntrinsics intrinsics_;
  std::size_t count_ = 0;
};

}  // namespace

Eigen::Isometry3d orthonormalized_pose(const Eigen::Matrix4d& matrix) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix.topLeftCorner<3, 3>(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  require(rotation.determinant() > 0, "pose matrix is a reflection, not a rotation");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation;
  pose.translation() = matrix.topRightCorner<3, 1>();
  return pose;
}

PinholeIntrinsics read_camera_intrinsics_json(const std::filesystem::path& path) {
  std::ifstream in = detail::open_text_file(path);
  nlohmann::json json;
  try {
    in >> json;
  } catch (const nlohmann::json::exception& e) {
    throw Error(quoted(path) + ": not valid JSON: " + e.what());
  }
  auto field = [&](const char* name) -> const nlohmann::json& {
    require(json.is_object() && json.contains(name), quoted(path) + ": missing field '" + name + "'");
    return json.at(name);
  };
  auto number = [&](const nlohmann::json& value, const std::string& what) {
    require(value.is_number() && std::isfinite(value.get<double>()),
            quoted(path) + ": field '" + what + "' must be a finite number");
    return value.get<double>();
  };
  auto integer = [&](const char* name) {
    const nlohmann::json& value = field(name);
    require(value.is_number_integer() && value.get<long long>() > 0 && value.get<long long>() <= 1 << 20,
            quoted(path) + ": field '" + name + "' must be a positive integer");
    return static_cast<int>(value.get<long long>());
  };
  const nlohmann::json& matrix = field("intrinsic_matrix");
  require(matrix.is_array() && matrix.size() == 9,
          quoted(path) + ": field 'intrinsic_matrix' must be an array of 9 numbers (column-major 3x3)");
  double m[9];
  for (int i = 0; i < 9; ++i) m[i] = number(matrix[i], "intrinsic_matrix[" + std::to_string(i) + "]");
  PinholeIntrinsics k;
  k.width = integer("width");
  k.height = integer("height");
  k.fx = m[0];
  k.fy = m[4];
  k.cx = m[6];
  k.cy = m[7];
  require(m[1] == 0 && m[2] == 0 && m[3] == 0 && m[5] == 0 && m[8] == 1,
          quoted(path) + ": field 'intrinsic_matrix' is not a pinhole matrix [fx 0 0 0 fy 0 cx cy 1] "
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

std::unique_ptr<Sequence> open_tum_sequence(const std::filesystem::path& folder, double max_difference,
                                            std::optional<PinholeIntrinsics> intrinsics) {
  const std::filesystem::path json = folder / "camera_intrinsics.json";
  if (!intrinsics && std::filesystem::exists(json)) intrinsics = read_camera_intrinsics_json(json);
  const PinholeIntrinsics k = intrinsics.value_or(PinholeIntrinsics{640, 480, 525.0, 525.0, 319.5, 239.5});
  k.validate("TUM intrinsics");
  return std::make_unique<TumSequence>(folder, max_difference, k);
}

std::unique_ptr<Sequence> open_seven_scenes(const std::filesystem::path& folder) {
  return std::make_unique<SevenScenesSequence>(folder);
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
      require(std::sscanf(line.c_str(), "%lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3]) == 4 &&
                  std::isfinite(v[0] + v[1] + v[2] + v[3]),
              quoted(path) + " line " + std::to_string(line_number) + ": expected 4 finite numbers");
      for (int c = 0; c < 4; ++c) m(r, c) = v[c];
    }
    StampedPose pose;
    pose.timestamp = static_cast<double>(trajectory.size());
    pose.pose = orthonormalized_pose(m);
    trajectory.push_back(pose);
  }
  return trajectory;
}

}  // namespace kartograf::io
