// A layout's frame list opened as the user asks: camera, depth scale, frame range, and bad frames
// either an Error naming the file or left out and reported; and the check that the depth is
// usable at all before a run starts.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "formats/atomic_file.hpp"
#include "formats/listed_sequence.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"

namespace kartograf::io {

namespace detail {

namespace {

// The frames first, first + step, ... of the list, at most count.
std::vector<std::pair<std::size_t, FrameFiles>> select_range(const FrameList& list,
                                                             const SequenceParams& o) {
  require(o.step >= 1, "frame step must be at least 1, got " + std::to_string(o.step));
  require(!o.count || *o.count > 0, "the number of frames must be at least 1");
  require(o.first < list.frames.size(), "first frame " + std::to_string(o.first) +
                                            " requested, the sequence has " +
                                            std::to_string(list.frames.size()) + " frames (0 to " +
                                            std::to_string(list.frames.size() - 1) + ")");
  std::vector<std::pair<std::size_t, FrameFiles>> selected;
  for (std::size_t i = o.first; i < list.frames.size(); i += o.step) {
    if (o.count && selected.size() == *o.count) break;
    selected.emplace_back(i, list.frames[i]);
    selected.back().second.position = i;
  }
  return selected;
}

std::vector<FrameFiles> files_of(const std::vector<std::pair<std::size_t, FrameFiles>>& frames) {
  std::vector<FrameFiles> files;
  for (const auto& frame : frames) files.push_back(frame.second);
  return files;
}

// Leaves out (skip) or refuses the frames that `bad` says cannot be used.
template <class Bad>
void drop_bad_frames(std::vector<std::pair<std::size_t, FrameFiles>>& frames, bool skip,
                     std::vector<SkippedFrame>& skipped, Bad&& bad) {
  std::vector<std::pair<std::size_t, FrameFiles>> kept;
  for (auto& frame : frames) {
    const std::string reason = bad(kept.size(), frame.second);
    if (reason.empty()) {
      kept.push_back(std::move(frame));
      continue;
    }
    require(skip, reason + " (frame " + std::to_string(frame.first) +
                      " of the sequence; --skip-bad-frames leaves such frames out)");
    skipped.push_back({frame.first, reason});
  }
  frames = std::move(kept);
  require(!frames.empty(), "no usable frame in the sequence (" + std::to_string(skipped.size()) +
                               " left out, e.g. " +
                               (skipped.empty() ? std::string("none") : skipped[0].reason) + ")");
}

// The camera with the first readable frame's size (the size every frame must have).
Camera camera_for_frames(std::vector<std::pair<std::size_t, FrameFiles>>& frames,
                         const Camera& camera, bool skip, std::vector<SkippedFrame>& skipped) {
  std::optional<DepthImage> first;
  drop_bad_frames(frames, skip, skipped, [&](std::size_t, const FrameFiles& files) {
    if (first) return std::string();
    try {
      first = read_depth_png(files.depth);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  });
  // A camera that does not fit is the camera's fault, not a frame's: never skipped.
  return fit_camera_to_frames(camera, first->width(), first->height());
}

}  // namespace

OpenedSequence open_listed(FrameList list, const SequenceParams& o) {
  OpenedSequence opened;
  Camera camera = list.camera;
  if (o.camera.empty()) {
    opened.warnings = list.camera_warnings;
  } else {
    camera = parse_camera_argument(o.camera);  // the user's: no default assumed
  }
  opened.warnings.insert(opened.warnings.end(), list.warnings.begin(), list.warnings.end());
  double scale = list.depth_units_per_metre;
  opened.depth_scale_source = list.depth_scale_source;
  if (o.depth_units_per_metre) {
    scale = *o.depth_units_per_metre;
    require(std::isfinite(scale) && scale > 0,
            "--depth-scale must be a positive number of depth units per metre, got " +
                std::to_string(scale));
    opened.depth_scale_source = "--depth-scale";
  }
  auto frames = select_range(list, o);
  drop_bad_frames(
      frames, o.skip_bad_frames, opened.skipped, [](std::size_t, const FrameFiles& files) {
        return files.missing.empty() ? std::string() : quoted(files.missing) + ": no such file";
      });
  opened.camera = camera_for_frames(frames, camera, o.skip_bad_frames, opened.skipped);
  auto sequence =
      std::make_unique<ListedSequence>(files_of(frames), opened.camera.intrinsics, scale);
  if (o.skip_bad_frames) {
    // Every frame read once: the bad ones are found before the run, not in the middle of it.
    drop_bad_frames(frames, true, opened.skipped, [&](std::size_t, const FrameFiles& files) {
      try {
        ListedSequence({files}, opened.camera.intrinsics, scale).frame(0);
      } catch (const Error& e) {
        return std::string(e.what());
      }
      return std::string();
    });
    sequence = std::make_unique<ListedSequence>(files_of(frames), opened.camera.intrinsics, scale);
  }
  opened.has_color = std::any_of(frames.begin(), frames.end(),
                                 [](const auto& frame) { return !frame.second.color.empty(); });
  opened.sequence = std::move(sequence);
  return opened;
}

}  // namespace detail

std::string describe_input(const OpenedSequence& opened) {
  char scale[64];
  std::snprintf(scale, sizeof(scale), "%g", opened.sequence->depth_units_per_metre());
  return "camera " + describe(opened.camera) + "; depth " + scale + " units per metre (" +
         opened.depth_scale_source + ")";
}

}  // namespace kartograf::io
