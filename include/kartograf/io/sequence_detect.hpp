#pragma once
// Opening an RGB-D sequence folder without being told its layout, and serving it to the mapping
// pipeline (mapping/frame_source.hpp).
//
// Layouts, checked in this order:
//   synthetic  rgb.txt, depth.txt and world.json: written by `kartograf synth` (a TUM folder with
//              camera_intrinsics.json and groundtruth.txt)
//   tum        rgb.txt and depth.txt (TUM RGB-D; camera_intrinsics.json when present)
//   7scenes    frame-000000.depth.png, in the folder or in its frames/ subfolder (7-Scenes has
//              no timestamps: frames are numbered)
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/io/sequence.hpp"
#include "kartograf/mapping/frame_source.hpp"

namespace kartograf::io {

enum class SequenceLayout { synthetic, tum, seven_scenes };
std::string_view to_string(SequenceLayout layout);  // "synthetic", "tum", "7scenes"

struct DetectedSequence {
  SequenceLayout layout = SequenceLayout::tum;
  bool has_timestamps = true;  // false: the frame number stands for the time
};

// Throws Error naming the folder and the files looked for when it matches no layout.
DetectedSequence detect_sequence(const std::filesystem::path& folder);

struct OpenedSequence {
  DetectedSequence detected;
  std::unique_ptr<Sequence> sequence;
};
OpenedSequence open_sequence(const std::filesystem::path& folder);

// A Sequence as the pipeline's FrameSource: frames [0, count) (count: all when empty or larger).
// Ground-truth poses are collected as frames are read, so that the caller can score a run
// without reading the frames again.
class SequenceFrameSource final : public mapping::FrameSource {
 public:
  explicit SequenceFrameSource(const Sequence& sequence,
                               std::optional<std::size_t> count = std::nullopt);

  std::size_t size() const override { return count_; }
  PinholeIntrinsics camera() const override { return sequence_->intrinsics(); }
  double depth_units_per_metre() const override { return sequence_->depth_units_per_metre(); }
  registration::RgbdImages frame(std::size_t i) const override;

  // Per frame read so far (index = frame): its ground-truth pose, if the data set has one.
  const std::vector<std::optional<Eigen::Isometry3d>>& ground_truth() const {
    return ground_truth_;
  }

 private:
  const Sequence* sequence_;
  std::size_t count_;
  // Written by frame(), which the pipeline calls from its prefetch thread one call at a time;
  // read after the run.
  mutable std::vector<std::optional<Eigen::Isometry3d>> ground_truth_;
};

}  // namespace kartograf::io
