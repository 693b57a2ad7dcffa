#pragma once
// One backend's part of the check: the copy bandwidth, every frame operation on every input, and
// the odometry over the real sequence compared with the CPU backend's poses.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "inputs.hpp"
#include "kartograf/compute/backend.hpp"
#include "measure.hpp"
#include "results.hpp"

namespace kartograf::gpu_check {

struct Inputs {
  FrameSet vga;       // 7-Scenes, 640x480
  FrameSet hd;        // the same frames enlarged to 1280x720
  FrameSet random;    // random depth and colour, 640x480
  OccupancyGrid map;  // office_e, for the laser scans
};

Inputs load_inputs(const std::filesystem::path& data_dir, int frames);

compute::BackendKind to_backend_kind(const std::string& name);  // throws Error for other names

// The CPU backend's poses over the real sequence, for the device backends to be compared with.
struct SequenceReference {
  std::vector<Eigen::Isometry3d> poses;
};

// Appends to `results`; false when the backend is available but an operation failed (the error
// is recorded). An unavailable backend is recorded as such and is not a failure.
bool run_backend(compute::BackendKind kind, const Inputs& inputs, const Repetitions& repetitions,
                 SequenceReference& reference, Results& results, std::ostream& log);

}  // namespace kartograf::gpu_check
