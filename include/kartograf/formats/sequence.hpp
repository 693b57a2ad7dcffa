#pragma once
// RGB-D sequences on disk, read lazily one frame at a time through one interface:
// TUM RGB-D folders (rgb.txt, depth.txt, optional groundtruth.txt), 7-Scenes / 3DMatch / SUN3D
// folders (frame-N.color.jpg or .color.png, frame-N.depth.png, frame-N.pose.txt, any first N) and
// rgb/ + depth/ folders; a folder with no colour image at all (depth/ alone, numbered depth
// frames without colour, TUM's depth.txt without rgb.txt) is a depth camera's: its frames'
// colour is empty. Also Redwood/Open3D
// .log trajectories. Opening a folder of any layout with
// a camera, depth scale, frame range and skipping of bad frames: io/sequence_detect.hpp.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/pose.hpp"
#include "kartograf/core/trajectory.hpp"

namespace kartograf::io {

struct RgbdFrame {
  std::size_t index = 0;  // position in the folder's order (before a frame range or skipping)
  double timestamp = 0;   // seconds
  RgbImage color;         // empty for a depth camera alone (OpenedSequence::has_color)
  DepthImage depth;
  std::optional<Eigen::Isometry3d> pose;  // camera-to-world ground truth, when the data set has it
  std::filesystem::path color_file, depth_file;  // where the images came from, for messages
};

class Sequence {
 public:
  virtual ~Sequence() = default;
  virtual std::size_t size() const = 0;
  // Loads frame i from disk; throws Error naming the file on a missing or corrupt image, a depth
  // image whose size is not the camera's, a colour image whose size is not the depth image's, or
  // a ground-truth pose that is not a rotation.
  virtual RgbdFrame frame(std::size_t i) const = 0;
  virtual PinholeIntrinsics intrinsics() const = 0;
  virtual double depth_units_per_metre() const = 0;
};

// A TUM RGB-D folder: rgb and depth associated within max_difference seconds (TUM's 0.02); the
// ground-truth pose is the nearest ground-truth sample within max_difference of the depth frame
// (frames without one have no pose). Intrinsics: the argument when given, else the folder's
// camera_intrinsics.json when present (see read_camera_intrinsics_json), else TUM's default
// Kinect (fx = fy = 525, cx = 319.5, cy = 239.5); depth scale 5000. Every listed file must exist.
std::unique_ptr<Sequence> open_tum_sequence(
    const std::filesystem::path& folder, double max_difference = 0.02,
    std::optional<PinholeIntrinsics> intrinsics = std::nullopt);

// Open3D's PinholeCameraIntrinsic JSON: {"width": W, "height": H, "intrinsic_matrix": [9 numbers]},
// the 3x3 matrix column-major ([fx, 0, 0, 0, fy, 0, cx, cy, 1]). Errors name the file and field.
PinholeIntrinsics read_camera_intrinsics_json(const std::filesystem::path& path);
// Writes that format (atomic).
void write_camera_intrinsics_json(const std::filesystem::path& path,
                                  const PinholeIntrinsics& intrinsics);

// A 7-Scenes / 3DMatch / SUN3D folder (frames/ inside it, or the frames themselves): the frames
// frame-N.depth.png found by listing the folder, in the order of N (any first N); colour
// frame-N.color.jpg or .color.png; intrinsics from camera-intrinsics.txt in the frames' folder or
// its parent when present (else 7-Scenes' 585/320/240), depth in millimetres, timestamps N / 30 s.
// A number missing from the run (first, first + step, ..., last) or a frame with only one of its
// images is an Error naming the missing file.
std::unique_ptr<Sequence> open_seven_scenes(const std::filesystem::path& folder);

// A Redwood / Open3D .log trajectory: per frame a line "i j k" then a 4x4 row-major matrix;
// timestamps are the frame index. Rotations are checked (rotation_pose) and re-orthonormalised;
// errors name the file and line.
Trajectory read_redwood_log(const std::filesystem::path& path);

// The nearest rotation (SVD) of a 3x3 block: in core (kartograf/core/pose.hpp), so that code
// without io (the device tests) uses the same one.
using kartograf::orthonormalized_pose;

// A ground-truth pose as data sets store it: accepted when its 3x3 block is a rotation up to
// kPoseRotationTolerance (||R^T R - I|| under it, det > 0; 7-Scenes' files are ~4e-4 off) and its
// last row is 0 0 0 1, then re-orthonormalised. Otherwise an Error starting with `where` (the
// file, and line) that says what is wrong.
inline constexpr double kPoseRotationTolerance = 1e-2;
Eigen::Isometry3d rotation_pose(const Eigen::Matrix4d& matrix, const std::string& where);

}  // namespace kartograf::io
