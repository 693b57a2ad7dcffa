#pragma once
// Where the mapping pipeline gets its frames: an interface that the io layer implements over a
// sequence on disk (io/sequence_detect.hpp) and tests implement over rendered frames, and the loop
// that reads frame i + 1 on a second thread while frame i is processed (decoding a 640x480 PNG
// pair costs about as much as registering it).
#include <cstddef>
#include <functional>

#include "kartograf/core/intrinsics.hpp"
#include "kartograf/registration/rgbd_frame.hpp"

namespace kartograf::mapping {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::size_t size() const = 0;
  virtual PinholeIntrinsics camera() const = 0;
  virtual double depth_units_per_metre() const = 0;
  // Frame i (throws Error on unreadable data). Called from a second thread, one call at a time.
  virtual registration::RgbdImages frame(std::size_t i) const = 0;
};

struct FrameLoopTiming {
  double wall_seconds = 0;     // the whole loop
  double load_seconds = 0;     // reading frames, on the prefetch thread
  double waiting_seconds = 0;  // the loop stood still waiting for a frame
};

// Calls visit(i, frame) for i in [first, last) in order while the next frame loads. An exception
// from loading or from visit propagates once the prefetch has finished.
FrameLoopTiming for_each_frame(
    const FrameSource& source, std::size_t first, std::size_t last,
    const std::function<void(std::size_t, registration::RgbdImages&)>& visit);

}  // namespace kartograf::mapping
