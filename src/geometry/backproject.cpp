#include "kartograf/geometry/backproject.hpp"

#include <cmath>
#include <limits>

#include "kartograf/compute/kernel.hpp"
#include "kernels/backproject/backproject.h"

namespace kartograf::geometry {

namespace {

constexpr compute::KernelSpec kBackprojectKernel{"backproject", KG_BACKPROJECT_LOCAL_X,
                                                 KG_BACKPROJECT_LOCAL_Y};

// The smallest raw value d with d / units >= metres, evaluated exactly as the reference does.
std::uint32_t first_unit_at_least(double metres, double units) {
  double d = std::max(0.0, std::ceil(metres * units));
  while (d > 0 && (d - 1) / units >= metres) d -= 1;
  while (d / units < metres) d += 1;
  return static_cast<std::uint32_t>(std::min(d, 65536.0));
}

}  // namespace

DepthUnits valid_depth_units(const DepthRange& range) {
  require(std::isfinite(range.units_per_metre) && range.units_per_metre > 0,
          "depth back-projection: units_per_metre must be positive, got " +
              std::to_string(range.units_per_metre));
  require(std::isfinite(range.min_metres) && std::isfinite(range.max_metres) &&
              range.min_metres >= 0 && range.min_metres <= range.max_metres,
          "depth back-projection: need 0 <= min_metres <= max_metres, got " +
              std::to_string(range.min_metres) + " and " + std::to_string(range.max_metres));
  DepthUnits units;
  units.min =
      std::max<std::uint32_t>(1, first_unit_at_least(range.min_metres, range.units_per_metre));
  // The largest d with d / units <= max is one below the first with d / units > max.
  const std::uint32_t above =
      first_unit_at_least(std::nextafter(range.max_metres, std::numeric_limits<double>::infinity()),
                          range.units_per_metre);
  units.max = std::min<std::uint32_t>(0xffff, above == 0 ? 0 : above - 1);
  return units;
}

DepthBackprojector::DepthBackprojector(const compute::Context& context,
                                       const PinholeIntrinsics& intrinsics, const DepthRange& range)
    : context_(&context), intrinsics_(intrinsics), range_(range) {
  intrinsics.validate("depth back-projection intrinsics");
  const DepthUnits units = valid_depth_units(range);
  min_units_ = units.min;
  max_units_ = units.max;

  const double metres_per_unit = 1.0 / range.units_per_metre;
  metres_per_unit_ = static_cast<float>(metres_per_unit);
  factors_.resize(static_cast<std::size_t>(intrinsics.width + intrinsics.height));
  for (int x = 0; x < intrinsics.width; ++x) {
    factors_[x] = static_cast<float>((x - intrinsics.cx) / intrinsics.fx * metres_per_unit);
  }
  for (int y = 0; y < intrinsics.height; ++y) {
    factors_[intrinsics.width + y] =
        static_cast<float>((y - intrinsics.cy) / intrinsics.fy * metres_per_unit);
  }
  device_factors_ = compute::Buffer<float>::from_host(context, factors_);
}

void DepthBackprojector::run(const compute::DeviceImage<std::uint16_t>& depth,
                             compute::DeviceImage<Point4f>& points) const {
  const int width = intrinsics_.width;
  const int height = intrinsics_.height;
  require(depth.width() == width && depth.height() == height,
          "depth back-projection: depth image is " + std::to_string(depth.width()) + "x" +
              std::to_string(depth.height()) + " but the intrinsics are for " +
              std::to_string(width) + "x" + std::to_string(height));
  if (points.width() != width || points.height() != height) {
    points = compute::DeviceImage<Point4f>(*context_, width, height);
  }
  const kernels::BackprojectParams params{static_cast<std::uint32_t>(width),
                                          static_cast<std::uint32_t>(height), min_units_,
                                          max_units_, metres_per_unit_};
  compute::dispatch(*context_, kBackprojectKernel,
                    {depth.buffer(), device_factors_, points.buffer()}, params,
                    {compute::groups_for(width, kBackprojectKernel.local_x),
                     compute::groups_for(height, kBackprojectKernel.local_y)});
}

PointImage backproject(const compute::Context& context, const DepthImage& depth,
                       const PinholeIntrinsics& intrinsics, const DepthRange& range) {
  const DepthBackprojector projector(context, intrinsics, range);
  const auto device_depth = compute::DeviceImage<std::uint16_t>::from_host(context, depth);
  compute::DeviceImage<Point4f> points(context, intrinsics.width, intrinsics.height);
  projector.run(device_depth, points);
  return points.to_image();
}

}  // namespace kartograf::geometry
