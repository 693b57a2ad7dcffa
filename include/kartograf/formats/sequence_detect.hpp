#pragma once
// Opening an RGB-D sequence folder without being told its layout, and serving it to the mapping
// pipeline (mapping/frame_source.hpp).
//
// Layouts, checked in this order:
//   synthetic  rgb.txt, depth.txt and world.json: written by `kartograf synth` (a TUM folder with
//              camera_intrinsics.json and groundtruth.txt)
//   tum        rgb.txt and depth.txt (TUM RGB-D; camera_intrinsics.json when present)
//   7scenes    frame-N.depth.png (any N), in the folder or in its frames/ subfolder: 7-Scenes,
//              3DMatch, SUN3D (no timestamps: frames are numbered)
//   rgb-depth  rgb/ and depth/ subfolders of images, paired by file name (or, with different
//              names, by sorted order when both hold as many); no timestamps
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/formats/camera_intrinsics.hpp"
#include "kartograf/formats/sequence.hpp"

namespace kartograf::io {

enum class SequenceLayout { synthetic, tum, seven_scenes, rgb_depth_folders };
// "synthetic", "tum", "7scenes", "rgb-depth"
std::string_view to_string(SequenceLayout layout);

struct DetectedSequence {
  SequenceLayout layout = SequenceLayout::tum;
  bool has_timestamps = true;  // false: the frame number stands for the time
};

// Throws Error naming the folder and the files looked for when it matches no layout.
DetectedSequence detect_sequence(const std::filesystem::path& folder);

// How to read a folder where its own files do not say, or say it wrong.
struct SequenceParams {
  // Empty: the folder's (camera_intrinsics.json, camera-intrinsics.txt, a TUM folder name saying
  // freiburg1/2/3), else a default with a warning. Else what parse_camera_argument takes.
  std::string camera;
  std::optional<double> depth_units_per_metre;  // else the layout's (TUM 5000, others 1000)
  // Frames first, first + step, ... (positions in the folder's order, 0 = its first frame), at
  // most `count` of them (empty: to the end).
  std::size_t first = 0;
  std::optional<std::size_t> count;
  std::size_t step = 1;
  // A missing or unreadable frame (or a pose that is not a rotation) is left out and listed in
  // OpenedSequence::skipped instead of an Error; every frame is then read once when opening.
  bool skip_bad_frames = false;
};

struct SkippedFrame {
  std::size_t position = 0;  // in the folder's order
  std::string reason;        // names the file
};

struct OpenedSequence {
  DetectedSequence detected;
  std::unique_ptr<Sequence> sequence;
  Camera camera;                      // what sequence->intrinsics() is, and where it came from
  std::string depth_scale_source;     // e.g. "--depth-scale", "TUM default"
  std::vector<std::string> warnings;  // e.g. a default camera assumed: for the user
  std::vector<SkippedFrame> skipped;
  // False for a depth camera alone (no colour image in the folder at all: its frames' colour is
  // empty); a folder with some colour images needs them all.
  bool has_color = true;
};
// Throws Error naming the folder, an option or a file when the folder cannot be read as asked.
OpenedSequence open_sequence(const std::filesystem::path& folder,
                             const SequenceParams& options = {});

// One line for people: the camera and the depth scale a run uses.
std::string describe_input(const OpenedSequence& opened);

}  // namespace kartograf::io
