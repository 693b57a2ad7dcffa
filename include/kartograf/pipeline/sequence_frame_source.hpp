#pragma once
// Where the formats meet the pipeline: a sequence read from a folder (formats/sequence.hpp) as the
// pipeline's FrameSource, and the check before a run that its depth is usable at all.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/formats/sequence.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/mapping/frame_source.hpp"
#include "kartograf/mapping/slam.hpp"

namespace kartograf::pipeline {

// Unusable depth found before a run: throws Error naming the depth file, the depth scale, the
// values found and --depth-scale when fewer than half the measured pixels of the first frames
// (up to 5) lie within range (all zero; all beyond range, as when metres are stored as
// millimetres; most beyond it, as with a depth scale 10 times too small).
// The range's depth scale is the sequence's.
void check_depth_usable(const io::Sequence& sequence, geometry::DepthRange range);
// The same for one depth image read from `file`, at the range's depth scale.
void check_depth_usable(const DepthImage& depth, const std::filesystem::path& file,
                        const geometry::DepthRange& range);

// A Sequence as the pipeline's FrameSource: frames [0, count) (count: all when empty or larger).
// Ground-truth poses are collected as frames are read, so that the caller can score a run
// without reading the frames again.
class SequenceFrameSource final : public mapping::FrameSource {
 public:
  explicit SequenceFrameSource(const io::Sequence& sequence,
                               std::optional<std::size_t> count = std::nullopt);

  std::size_t size() const override { return count_; }
  PinholeIntrinsics camera() const override { return sequence_->intrinsics(); }
  double depth_units_per_metre() const override { return sequence_->depth_units_per_metre(); }
  registration::RgbdImages frame(std::size_t i) const override;

  // Per frame read so far (index = frame): its ground-truth pose, if the data set has one.
  const std::vector<std::optional<Eigen::Isometry3d>>& ground_truth() const {
    return ground_truth_;
  }

  // Every frame read from now on carries prior_of's pose as its motion prior
  // (RgbdImages::motion_prior: another sensor's camera poses); prior_of's Error stops the run.
  void set_motion_prior(mapping::KnownPoseLookup prior_of) { prior_of_ = std::move(prior_of); }

 private:
  const io::Sequence* sequence_;
  std::size_t count_;
  mapping::KnownPoseLookup prior_of_;
  // Written by frame(), which the pipeline calls from its prefetch thread one call at a time;
  // read after the run.
  mutable std::vector<std::optional<Eigen::Isometry3d>> ground_truth_;
};

}  // namespace kartograf::pipeline
