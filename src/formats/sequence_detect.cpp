#include "kartograf/formats/sequence_detect.hpp"

#include <string>

#include "formats/atomic_file.hpp"
#include "formats/listed_sequence.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::io {

namespace fs = std::filesystem;

std::string_view to_string(SequenceLayout layout) {
  switch (layout) {
    case SequenceLayout::synthetic:
      return "synthetic";
    case SequenceLayout::tum:
      return "tum";
    case SequenceLayout::seven_scenes:
      return "7scenes";
    case SequenceLayout::rgb_depth_folders:
      return "rgb-depth";
  }
  return "unknown";
}

DetectedSequence detect_sequence(const fs::path& folder) {
  require(fs::is_directory(folder), detail::quoted(folder) +
                                        ": not a folder (expected an RGB-D "
                                        "sequence folder)");
  // TUM: rgb.txt and depth.txt, or depth.txt alone (a depth camera's).
  if (fs::is_regular_file(folder / "depth.txt")) {
    const bool synthetic = fs::is_regular_file(folder / "world.json");
    return {synthetic ? SequenceLayout::synthetic : SequenceLayout::tum, true};
  }
  if (detail::numbered_frames_folder(folder)) return {SequenceLayout::seven_scenes, false};
  if (fs::is_directory(folder / "depth")) return {SequenceLayout::rgb_depth_folders, false};
  throw Error(detail::quoted(folder) +
              ": not a known RGB-D sequence layout (looked for rgb.txt and depth.txt, or "
              "depth.txt alone: TUM or kartograf synth; frame-N.depth.png (e.g. "
              "frame-000000.depth.png), in the folder or in frames/: 7-Scenes, 3DMatch, SUN3D; "
              "rgb/ and depth/ folders of images, or depth/ alone)");
}

OpenedSequence open_sequence(const fs::path& folder, const SequenceParams& options) {
  const DetectedSequence detected = detect_sequence(folder);
  detail::FrameList list;
  switch (detected.layout) {
    case SequenceLayout::seven_scenes:
      list = detail::list_numbered_frames(folder);
      break;
    case SequenceLayout::rgb_depth_folders:
      list = detail::list_rgb_depth_frames(folder);
      break;
    default:
      list = detail::list_tum_frames(folder, 0.02);
  }
  OpenedSequence opened = detail::open_listed(std::move(list), options);
  opened.detected = detected;
  return opened;
}

}  // namespace kartograf::io
