#include "kartograf/pipeline/sequence_frame_source.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>

#include "formats/atomic_file.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::pipeline {

namespace detail = io::detail;

SequenceFrameSource::SequenceFrameSource(const io::Sequence& sequence,
                                         std::optional<std::size_t> count)
    : sequence_(&sequence), count_(count && *count < sequence.size() ? *count : sequence.size()) {}

registration::RgbdImages SequenceFrameSource::frame(std::size_t i) const {
  require(i < count_, "sequence frame " + std::to_string(i) + " requested, the run has " +
                          std::to_string(count_) + " frames");
  io::RgbdFrame frame = sequence_->frame(i);
  if (ground_truth_.size() <= i) ground_truth_.resize(i + 1);
  ground_truth_[i] = frame.pose;
  registration::RgbdImages images{std::move(frame.depth), std::move(frame.color), frame.timestamp,
                                  frame.pose};
  if (prior_of_) images.motion_prior = prior_of_(i, images);
  return images;
}

void check_depth_usable(const io::Sequence& sequence, const geometry::DepthRange& range) {
  const double units = sequence.depth_units_per_metre();
  std::filesystem::path first_file;
  const std::size_t checked = std::min<std::size_t>(sequence.size(), 5);
  std::uint32_t low = std::numeric_limits<std::uint32_t>::max(), high = 0;
  for (std::size_t i = 0; i < checked; ++i) {
    const io::RgbdFrame frame = sequence.frame(i);
    if (i == 0) first_file = frame.depth_file;
    for (const std::uint16_t value : frame.depth.pixels()) {
      if (value == 0) continue;
      low = std::min<std::uint32_t>(low, value);
      high = std::max<std::uint32_t>(high, value);
      const double metres = value / units;
      if (metres >= range.min_metres && metres <= range.max_metres) return;
    }
  }
  char text[320];
  if (high == 0) {
    std::snprintf(text, sizeof(text), "every depth value is 0 (no measurement)");
  } else {
    std::snprintf(text, sizeof(text), "values %u to %u, i.e. %.3g to %.3g m", low, high,
                  low / units, high / units);
  }
  char limits[160];
  std::snprintf(limits, sizeof(limits), "%g to %g m at a depth scale of %g units per metre",
                range.min_metres, range.max_metres, units);
  const std::string others =
      checked > 1 ? " (and the next " + std::to_string(checked - 1) + " frames)" : "";
  throw Error("depth image " + detail::quoted(first_file) + others +
              ": no pixel within the usable depth range, " + limits + " (" + text +
              "); if the depth is stored in other units, give them with --depth-scale "
              "(units per metre: 1000 for millimetres, 5000 for TUM)");
}

}  // namespace kartograf::pipeline
