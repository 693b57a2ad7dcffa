#pragma once
// The inputs every method of the peer benchmark sees: RGB-D sequences with ground truth, frame
// pairs taken from them, and the point clouds of those frames (full and downsampled to ~20k
// points). Clouds are made once with Kartograf (back-projection, organized normals, voxel
// downsampling on the CPU backend) and handed unchanged to Kartograf, Open3D and PCL, so the
// methods differ only in registration, never in their input or its normals.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_cloud.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/geometry/backproject.hpp"

namespace kartograf::peer {

struct Frame {
  std::size_t index = 0;
  RgbImage color;
  DepthImage depth;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // camera-to-world ground truth
};

struct Dataset {
  std::string name;
  std::string note;  // what a reader must know about it (e.g. colour not registered to depth)
  std::unique_ptr<io::Sequence> sequence;
  geometry::DepthRange range;  // the same depth range for every method
  PinholeIntrinsics camera() const { return sequence->intrinsics(); }
  std::size_t size() const { return sequence->size(); }
  // Throws Error when the frame has no ground-truth pose.
  Frame frame(std::size_t index) const;
};

// Every method gets the same depth range: the 7-Scenes sensor's valid range ends near 3.5 m and
// Open3D's odometry ignores depth beyond 4 m by default.
inline constexpr double kMinDepthMetres = 0.1;
inline constexpr double kMaxDepthMetres = 4.0;

// A 7-Scenes folder (depth in millimetres, fx = fy = 585, cx = 320, cy = 240).
Dataset open_seven_scenes_dataset(const std::filesystem::path& folder);
// A TUM folder written by `kartograf synth` / io::write_synthetic_dataset.
Dataset open_synthetic_dataset(const std::filesystem::path& folder);
// Writes a hand-held synthetic sequence of `frames` frames into `folder` (replacing one there).
void write_synthetic_sequence(const std::filesystem::path& folder, int frames);

// Valid points of one frame with their normals and colours; the colour of a point is the colour
// image's pixel at the depth pixel (approximate where the two cameras are not registered).
struct FrameClouds {
  PointCloud full;     // every valid point with a valid normal
  PointCloud sampled;  // voxel-downsampled full cloud (centroids, mean normals and colours)
};

// Cuts the clouds of frames with the dataset's camera and range. The voxel size is chosen once,
// on the first frame, so that its cloud has ~target_points points; all frames then use it.
class CloudMaker {
 public:
  CloudMaker(const Dataset& dataset, std::size_t target_points);
  FrameClouds make(const Frame& frame) const;
  double voxel_size() const { return voxel_size_; }

 private:
  PointCloud full_cloud(const Frame& frame) const;
  const Dataset* dataset_;
  std::size_t target_points_;
  double voxel_size_ = 0;
};

// Frames source_index (the newer) and target_index of one dataset; truth maps source-camera
// points into the target camera (T_target^-1 T_source), what every method estimates.
struct FramePair {
  const Dataset* dataset = nullptr;
  Frame source, target;
  FrameClouds source_clouds, target_clouds;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  int gap() const { return static_cast<int>(source.index - target.index); }
  std::string label() const;  // "7scenes 120->125"
};

// Pairs (i + gap, i) for each start i and gap.
std::vector<FramePair> make_pairs(const Dataset& dataset, const CloudMaker& clouds,
                                  const std::vector<std::size_t>& starts,
                                  const std::vector<int>& gaps);

}  // namespace kartograf::peer
