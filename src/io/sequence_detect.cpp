#include "kartograf/io/sequence_detect.hpp"

#include <string>

#include "io/atomic_file.hpp"
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
  const char* first_frame = "frame-000000.depth.png";
  if (fs::is_regular_file(folder / first_frame) ||
      fs::is_regular_file(folder / "frames" / first_frame)) {
    return {SequenceLayout::seven_scenes, false};
  }
  throw Error(
      detail::quoted(folder) +
      ": not a known RGB-D sequence layout (looked for rgb.txt and depth.txt: TUM or "
      "kartograf synth; frame-000000.depth.png or frames/frame-000000.depth.png: 7-Scenes)");
}

OpenedSequence open_sequence(const fs::path& folder) {
  OpenedSequence opened;
  opened.detected = detect_sequence(folder);
  opened.sequence = opened.detected.layout == SequenceLayout::seven_scenes
                        ? open_seven_scenes(folder)
                        : open_tum_sequence(folder);
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
