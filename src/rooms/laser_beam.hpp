#pragma once
// One beam of a simulated laser scan in the integer arithmetic that LaserScanner, the CPU backend
// of DeviceLaserScanner, shaders/laser_scan.comp and kernels/laser_scan.cl share (rules in
// include/kartograf/rooms/laser_features.hpp). No floating point: every backend agrees bit for bit.
#include <algorithm>
#include <cstdint>

namespace kartograf::rooms::detail {

// The step count of the beam with direction (dx, dy) [1/65536 cells per step] from the fixed-point
// position (x0, y0) in the padded grid `skips` (row stride `stride`), at most max_steps.
inline std::int32_t trace_beam(const std::int32_t* skips, std::int32_t stride, std::int32_t x0,
                               std::int32_t y0, std::int32_t dx, std::int32_t dy,
                               std::int32_t max_steps) {
  std::int32_t step = 0;
  while (step < max_steps) {
    // Samples stay inside the padded grid (its border ring stops every beam), so positions are
    // >= 0 and below 2^31: the shift is a floor and nothing overflows.
    const std::int32_t x = (x0 + step * dx) >> 16, y = (y0 + step * dy) >> 16;
    const std::int32_t skip = skips[static_cast<std::int64_t>(y) * stride + x];
    if (skip == 0) break;
    step += skip;
  }
  return std::min(step, max_steps);
}

}  // namespace kartograf::rooms::detail
