#include "kartograf/pipeline/sequence_frame_source.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

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

namespace {

// The non-zero depth values of a sequence's first frames (up to 5) or of one depth image, against
// the usable range.
struct DepthSurvey {
  std::filesystem::path first_file;
  std::size_t frames = 0;
  std::uint64_t measured = 0, usable = 0;  // non-zero pixels; those within the range
  std::uint32_t low = std::numeric_limits<std::uint32_t>::max(), high = 0;
  std::vector<std::uint16_t> values;  // the non-zero values, for their median
};

void add_depth(const DepthImage& depth, const geometry::DepthRange& range, DepthSurvey& survey) {
  for (const std::uint16_t value : depth.pixels()) {
    if (value == 0) continue;
    ++survey.measured;
    survey.values.push_back(value);
    survey.low = std::min<std::uint32_t>(survey.low, value);
    survey.high = std::max<std::uint32_t>(survey.high, value);
    const double metres = value / range.units_per_metre;
    survey.usable += metres >= range.min_metres && metres <= range.max_metres;
  }
}

template <class... Numbers>
std::string format_text(const char* format, Numbers... numbers) {
  char text[200];
  std::snprintf(text, sizeof(text), format, numbers...);
  return text;
}

void check_survey(DepthSurvey s, const geometry::DepthRange& range) {
  const double units = range.units_per_metre;
  // Most of a depth camera's pixels lie within its range; most of them outside it (a depth
  // scale 10 times too small, millimetres read as TUM's fifths, SUN RGB-D's bit-rotated values
  // read as millimetres) leaves a run on the few that fall inside, silently wrong.
  if (s.usable > 0 && 2 * s.usable >= s.measured) return;
  const std::string limits = format_text("%g to %g m at a depth scale of %g units per metre",
                                         range.min_metres, range.max_metres, units);
  std::string found;
  if (s.high == 0) {
    found = "every depth value is 0 (no measurement)";
  } else {
    std::nth_element(s.values.begin(), s.values.begin() + s.values.size() / 2, s.values.end());
    found = "values " + std::to_string(s.low) + " to " + std::to_string(s.high) +
            format_text(", i.e. %.3g to %.3g m, median %.3g m", s.low / units, s.high / units,
                        s.values[s.values.size() / 2] / units);
  }
  const std::string within =
      s.usable == 0
          ? "no pixel within the usable depth range, "
          : format_text("only %.0f %% of the measured pixels within the usable depth range, ",
                        100.0 * static_cast<double>(s.usable) / static_cast<double>(s.measured));
  const std::string others =
      s.frames > 1 ? " (and the next " + std::to_string(s.frames - 1) + " frames)" : "";
  throw Error("depth image " + detail::quoted(s.first_file) + others + ": " + within + limits +
              " (" + found +
              "); if the depth is stored in other units, give them with --depth-scale "
              "(units per metre: 1000 for millimetres, 5000 for TUM)");
}

}  // namespace

void check_depth_usable(const io::Sequence& sequence, geometry::DepthRange range) {
  range.units_per_metre = sequence.depth_units_per_metre();
  DepthSurvey survey;
  survey.frames = std::min<std::size_t>(sequence.size(), 5);
  for (std::size_t i = 0; i < survey.frames; ++i) {
    const io::RgbdFrame frame = sequence.frame(i);
    if (i == 0) survey.first_file = frame.depth_file;
    add_depth(frame.depth, range, survey);
  }
  check_survey(std::move(survey), range);
}

void check_depth_usable(const DepthImage& depth, const std::filesystem::path& file,
                        const geometry::DepthRange& range) {
  DepthSurvey survey;
  survey.first_file = file;
  survey.frames = 1;
  add_depth(depth, range, survey);
  check_survey(std::move(survey), range);
}

}  // namespace kartograf::pipeline
