#pragma once
// Depth back-projection (docs/methods.md M1 step 1): a 16-bit depth image becomes an organized
// cloud of float4 points (x, y, z, 1) in the camera frame, all-NaN where the depth is 0 or outside
// the range. Every coordinate is d * k with k rounded once from double, so each is within
// 1.2e-7 * |coordinate| of the exact value (<= 1e-6 m up to 8 m) on every backend.
#include <cstdint>
#include <vector>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::geometry {

struct DepthRange {
  double units_per_metre = 1000.0;  // 1000: millimetres (Kinect, 7-Scenes); 5000: TUM RGB-D
  double min_metres = 0.1;
  double max_metres = 10.0;
};

// The inclusive range of raw depth values that count as valid (never 0); Error when the range
// is not a finite 0 <= min <= max with positive units.
struct DepthUnits {
  std::uint32_t min = 1;
  std::uint32_t max = 0xffff;
};
DepthUnits valid_depth_units(const DepthRange& range);

// Back-projects depth frames of one camera; the per-camera tables live on the device.
class DepthBackprojector {
 public:
  // Throws Error on invalid intrinsics or range.
  DepthBackprojector(const compute::Context& context, const PinholeIntrinsics& intrinsics,
                     const DepthRange& range);

  // depth and points must be intrinsics.width x intrinsics.height (points is resized if empty).
  void run(const compute::DeviceImage<std::uint16_t>& depth,
           compute::DeviceImage<Point4f>& points) const;

  const PinholeIntrinsics& intrinsics() const { return intrinsics_; }
  // The inclusive range of raw depth values that count as valid.
  std::uint32_t min_units() const { return min_units_; }
  std::uint32_t max_units() const { return max_units_; }

 private:
  const compute::Context* context_;
  PinholeIntrinsics intrinsics_;
  DepthRange range_;
  std::uint32_t min_units_ = 1;
  std::uint32_t max_units_ = 0xffff;
  float metres_per_unit_ = 0;
  std::vector<float> factors_;  // column factors then row factors (host copy for the CPU path)
  compute::Buffer<float> device_factors_;
};

// Convenience: one host frame in, one host point image out.
PointImage backproject(const compute::Context& context, const DepthImage& depth,
                       const PinholeIntrinsics& intrinsics, const DepthRange& range = {});

}  // namespace kartograf::geometry
