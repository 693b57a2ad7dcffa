#pragma once
// Every layout (TUM, 7-Scenes / 3DMatch / SUN3D, rgb/ + depth/) comes down to a list of frames'
// files, a camera and a depth scale; one Sequence reads such a list and checks each frame the same
// way. The layouts list their frames in sequence_layouts.cpp; open_sequence (sequence_detect.cpp)
// applies the user's options to the list.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/formats/camera_intrinsics.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/formats/sequence_detect.hpp"

namespace kartograf::io::detail {

struct FrameFiles {
  double timestamp = 0;  // seconds
  std::filesystem::path color, depth;
  std::filesystem::path pose_file;        // a 4x4 camera-to-world matrix; empty: none
  std::optional<Eigen::Isometry3d> pose;  // already known (TUM's groundtruth.txt)
  std::filesystem::path missing;          // a file of the frame that is not there, else empty
  std::size_t position = 0;               // in the folder's order (RgbdFrame::index)
};

struct FrameList {
  std::vector<FrameFiles> frames;
  Camera camera;  // the layout's own, may lack the image size
  double depth_units_per_metre = 1000;
  std::string depth_scale_source;
  // A default camera assumed (dropped when the user gives one), and the other warnings.
  std::vector<std::string> camera_warnings, warnings;
};

// TUM (and kartograf synth) folders: rgb.txt and depth.txt associated within max_difference s.
FrameList list_tum_frames(const std::filesystem::path& folder, double max_difference);
// 7-Scenes / 3DMatch / SUN3D: frame-N.* in the folder or its frames/ subfolder.
FrameList list_numbered_frames(const std::filesystem::path& folder);
// rgb/ and depth/ subfolders.
FrameList list_rgb_depth_frames(const std::filesystem::path& folder);

// frame-N.depth.png in `folder` or its frames/ subfolder (where the frames are), if any.
std::optional<std::filesystem::path> numbered_frames_folder(const std::filesystem::path& folder);

// The list as the options ask (camera, depth scale, range, bad frames), opened. Throws Error
// naming the missing or unreadable file, or the option.
OpenedSequence open_listed(FrameList list, const SequenceParams& options);

class ListedSequence final : public Sequence {
 public:
  // camera must have its size; frames their files checked for existence.
  ListedSequence(std::vector<FrameFiles> frames, const PinholeIntrinsics& camera,
                 double depth_units_per_metre);

  std::size_t size() const override { return frames_.size(); }
  PinholeIntrinsics intrinsics() const override { return camera_; }
  double depth_units_per_metre() const override { return depth_units_per_metre_; }
  RgbdFrame frame(std::size_t i) const override;

 private:
  std::vector<FrameFiles> frames_;
  PinholeIntrinsics camera_;
  double depth_units_per_metre_;
};

}  // namespace kartograf::io::detail
