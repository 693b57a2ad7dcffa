#include "kartograf/io/sequence_detect.hpp"

#include <string>

#include "io/atomic_file.hpp"
#include "io/listed_sequence.hpp"
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
  if (fs::is_regular_file(folder / "rgb.txt") && fs::is_regular_file(folder / "depth.txt")) {
    const bool synthetic = fs::is_regular_file(folder / "world.json");
    return {synthetic ? SequenceLayout::synthetic : SequenceLayout::tum, true};
  }
  if (detail::numbered_frames_folder(folder)) return {SequenceLayout::seven_scenes, false};
  if (fs::is_directory(folder / "rgb") && fs::is_directory(folder / "depth"))
    return {SequenceLayout::rgb_depth_folders, false};
  throw Error(detail::quoted(folder) +
              ": not a known RGB-D sequence layout (looked for rgb.txt and depth.txt: TUM or "
              "kartograf synth; frame-N.depth.png (e.g. frame-000000.depth.png), in the folder "
              "or in frames/: 7-Scenes, 3DMatch, SUN3D; rgb/ and depth/ folders of images)");
}

OpenedSequence open_sequence(const fs::path& folder, const SequenceOptions& options) {
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

SequenceFrameSource::SequenceFrameSource(const Sequence& sequence, std::optional<std::size_t> count)
    : sequence_(&sequence), count_(count && *count < sequence.size() ? *count : sequence.size()) {}

registration::RgbdImages SequenceFrameSource::frame(std::size_t i) const {
  require(i < count_, "sequence frame " + std::to_string(i) + " requested, the run has " +
                          std::to_string(count_) + " frames");
  RgbdFrame frame = sequence_->frame(i);
  if (ground_truth_.size() <= i) ground_truth_.resize(i + 1);
  ground_truth_[i] = frame.pose;
  return {std::move(frame.depth), std::move(frame.color), frame.timestamp};
}

}  // namespace kartograf::io
