#pragma once
// The device operations the check times, on one frame set resident on one context. Each call of an
// operation processes the next frame of the set (so caches never hold a whole answer); inputs are
// uploaded once, before timing, except where the operation is the upload itself.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "inputs.hpp"
#include "kartograf/compute/context.hpp"

namespace kartograf::gpu_check {

struct Workspace;  // device images, pyramids, reducers (frame_ops.cpp)

struct Operation {
  std::string name;
  // Bytes a perfect implementation must move per pixel of the frame (reads + writes of global
  // memory), for the bandwidth floor; 0 where the figure means nothing (host copies, whole ICP).
  double bytes_per_pixel = 0;
  std::function<void(Workspace&)> call;
};

const std::vector<Operation>& frame_operations();

// Builds the workspace (uploads, the reference pyramid) and finishes; throws Error from the
// backend (e.g. a shader the driver rejects).
std::shared_ptr<Workspace> make_workspace(const compute::Context& context, const FrameSet& frames);

}  // namespace kartograf::gpu_check
