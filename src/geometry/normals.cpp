#include "kartograf/geometry/normals.hpp"

#include <cmath>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kernels/normals/normals.h"

namespace kartograf::geometry {

namespace {

constexpr compute::KernelSpec kNormalsKernel{"normals", KG_NORMALS_LOCAL_X, KG_NORMALS_LOCAL_Y};

}  // namespace

void estimate_normals(const compute::Context& context, const compute::DeviceImage<Point4f>& points,
                      compute::DeviceImage<Point4f>& normals, const NormalParams& params) {
  require(std::isfinite(params.max_depth_jump) && params.max_depth_jump > 0,
          "normal estimation: max_depth_jump must be positive, got " +
              std::to_string(params.max_depth_jump));
  const int width = points.width();
  const int height = points.height();
  if (normals.width() != width || normals.height() != height) {
    normals = compute::DeviceImage<Point4f>(context, width, height);
  }
  if (width == 0 || height == 0) return;
  const kernels::NormalsParams kernel_params{static_cast<std::uint32_t>(width),
                                         static_cast<std::uint32_t>(height), params.max_depth_jump};
  compute::dispatch(context, kNormalsKernel, {points.buffer(), normals.buffer()}, kernel_params,
                    {compute::groups_for(width, kNormalsKernel.local_x),
                     compute::groups_for(height, kNormalsKernel.local_y)});
}

NormalImage estimate_normals(const compute::Context& context, const PointImage& points,
                             const NormalParams& params) {
  const auto device_points = compute::DeviceImage<Point4f>::from_host(context, points);
  compute::DeviceImage<Point4f> normals(context, points.width(), points.height());
  estimate_normals(context, device_points, normals, params);
  return normals.to_image();
}

}  // namespace kartograf::geometry
