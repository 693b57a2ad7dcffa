#include "kartograf/geometry/normals.hpp"

#include <cmath>
#include <string>

#include "kartograf/compute/kernel.hpp"

namespace kartograf::geometry {

namespace {

constexpr compute::KernelSpec kNormalsKernel{"normals", 16, 16};

struct NormalKernelParams {  // layout of shaders/normals.comp and kernels/normals.cl
  std::uint32_t width;
  std::uint32_t height;
  float max_depth_jump;
};

// Plain float arithmetic in the order the shader and kernel use, so all backends agree.
struct Vec3 {
  float x, y, z;
};
Vec3 operator-(const Point4f& a, const Point4f& b) { return {a.x() - b.x(), a.y() - b.y(), a.z() - b.z()}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

bool usable(const Point4f& neighbour, const Point4f& centre, float max_depth_jump) {
  return is_valid(neighbour) && std::fabs(neighbour.z() - centre.z()) <= max_depth_jump * centre.z();
}

// One tangent from the neighbours before and after the centre; false when there is none.
bool tangent(const Point4f& before, const Point4f& centre, const Point4f& after, float max_depth_jump,
             Vec3& result) {
  const bool has_before = usable(before, centre, max_depth_jump);
  const bool has_after = usable(after, centre, max_depth_jump);
  if (has_before && has_after) {
    result = after - before;
  } else if (has_after) {
    result = after - centre;
  } else if (has_before) {
    result = centre - before;
  } else {
    return false;
  }
  return true;
}

void normals_cpu(const Point4f* points, int width, int height, float max_depth_jump, Point4f* normals) {
  const Point4f invalid = invalid_point();
  auto at = [&](int x, int y) -> const Point4f& {
    if (x < 0 || y < 0 || x >= width || y >= height) return invalid;
    return points[static_cast<std::size_t>(y) * width + x];
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Point4f& centre = at(x, y);
      Point4f& out = normals[static_cast<std::size_t>(y) * width + x];
      out = invalid;
      Vec3 along_x{}, along_y{};
      if (!is_valid(centre) || !tangent(at(x - 1, y), centre, at(x + 1, y), max_depth_jump, along_x) ||
          !tangent(at(x, y - 1), centre, at(x, y + 1), max_depth_jump, along_y)) {
        continue;
      }
      Vec3 n = cross(along_x, along_y);
      const float length_sq = dot(n, n);
      if (!(length_sq > 1e-12f * dot(along_x, along_x) * dot(along_y, along_y))) continue;
      const float inverse_length = 1.0f / std::sqrt(length_sq);
      const float sign = (n.x * centre.x() + n.y * centre.y() + n.z * centre.z()) > 0.0f ? -1.0f : 1.0f;
      out = Point4f(sign * n.x * inverse_length, sign * n.y * inverse_length,
                    sign * n.z * inverse_length, 0.0f);
    }
  }
}

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
  if (context.is_cpu()) {
    normals_cpu(points.buffer().host_span().data(), width, height, params.max_depth_jump,
                normals.buffer().host_span().data());
    return;
  }
  const NormalKernelParams kernel_params{static_cast<std::uint32_t>(width),
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
