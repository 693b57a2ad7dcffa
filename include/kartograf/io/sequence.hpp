#pragma once
// RGB-D sequences on disk, read lazily one frame at a time through one interface:
// TUM RGB-D folders (rgb.txt, depth.txt, optional groundtruth.txt) and 7-Scenes folders
// (frame-N.color.jpg, frame-N.depth.png, frame-N.pose.txt). Also Redwood/Open3D .log trajectories.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/trajectory.hpp"

namespace kartograf::io {

struct RgbdFrame {
  std::size_t index = 0;
  double timestamp = 0;  // seconds
  RgbImage color;
  DepthImage depth;
  std::optional<Eigen::Isometry3d> pose;  // camera-to-world ground truth, when the data set has it
};

class Sequence {
 public:
  virtual ~Sequence() = default;
  virtual std::size_t size() const = 0;
  // Loads frame i from disk; throws Error naming the file on a missing or corrupt image.
  virtual RgbdFrame frame(std::size_t i) const = 0;
  virtual PinholeIntrinsics intrinsics() const = 0;
  virtual double depth_units_per_metre() const = 0;
};

// A TUM RGB-D folder: rgb and depth associated within max_difference seconds (TUM's 0.02); the
// ground-truth pose is the nearest ground-truth sample within max_difference of the depth frame
// (frames without one have no pose). Intrinsics: the argument when given, else the folder's
// camera_intrinsics.json when present (see read_camera_intrinsics_json), else TUM's default
// Kinect (fx = fy = 525, cx = 319.5, cy = 239.5); depth scale 5000.
std::unique_ptr<Sequence> open_tum_sequence(const std::filesystem::path& folder,
                                            double max_difference = 0.02,
                                            std::optional<PinholeIntrinsics> intrinsics = std::nullopt);

// Open3D's PinholeCameraIntrinsic JSON: {"width": W, "height": H, "intrinsic_matrix": [9 numbers]},
// the 3x3 matrix column-major ([fx, 0, 0, 0, fy, 0, cx, cy, 1]). Errors name the file and field.
PinholeIntrinsics read_camera_intrinsics_json(const std::filesystem::path& path);
// Writes that format (atomic).
void write_camera_intrinsics_json(const std::filesystem::path& path, const PinholeIntrinsics& intrinsics);

// A 7-Scenes folder (frames/ inside it, or the frames themselves): intrinsics from
// camera-intrinsics.txt when present (else 585/320/240), depth in millimetres, poses
// re-orthonormalised (the files carry ~1e-4 of non-orthonormality), timestamps index / 30 s.
std::unique_ptr<Sequence> open_seven_scenes(const std::filesystem::path& folder);

// A Redwood / Open3D .log trajectory: per frame a line "i j k" then a 4x4 row-major matrix;
// timestamps are the frame index. Rotations are re-orthonormalised.
Trajectory read_redwood_log(const std::filesystem::path& path);

// The nearest rotation (SVD) of a 3x3 block, and the pose made of it and a translation.
Eigen::Isometry3d orthonormalized_pose(const Eigen::Matrix4d& matrix);

}  // namespace kartograf::io
