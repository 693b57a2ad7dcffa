#pragma once
// Timing one call many times on one context: wall clock per call (dispatch to finish), the device's
// own time per call (the sum of its commands' timestamps, when the context profiles), and each
// command's device time per call. Warm-up calls are run first and not counted.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"

namespace kartograf::gpu_check {

struct Samples {
  std::vector<double> wall_ms;    // one per timed call
  std::vector<double> device_ms;  // one per timed call; empty without device timestamps
  std::map<std::string, std::vector<double>> command_ms;  // per command name, summed per call
};

double median(std::vector<double> values);  // 0 for an empty list

struct Repetitions {
  int warm_up = 3;
  int timed = 30;
};

// call() issues the work; finish() and the timing reads are done here. A call whose first warm-up
// takes over 20 ms (the CPU backend's voxel hash, laser scans) is timed 5 times after one
// warm-up, so that the whole check stays within its few minutes.
Samples measure(const compute::Context& context, const Repetitions& repetitions,
                const std::function<void()>& call);

}  // namespace kartograf::gpu_check
