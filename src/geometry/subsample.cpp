#include "kartograf/geometry/subsample.hpp"

#include <string>
#include <vector>

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/color.hpp"
#include "kernels/subsample/subsample.h"

namespace kartograf::geometry {

namespace {

constexpr compute::KernelSpec kSubsampleKernel{"subsample", KG_SUBSAMPLE_LOCAL_X};

}  // namespace

void DeviceCloud::validate(const std::string& what) const {
  require(!has_normals() || normals.size() == size(), what + ": " + std::to_string(normals.size()) +
                                                          " normals for " + std::to_string(size()) +
                                                          " points");
  require(!has_colors() || colors.size() == size(), what + ": " + std::to_string(colors.size()) +
                                                        " colours for " + std::to_string(size()) +
                                                        " points");
  require(size() < (std::size_t{1} << 31), what + ": more than 2^31 points");
}

DeviceCloud DeviceCloud::from_host(const compute::Context& context, const PointCloud& cloud) {
  require(!cloud.has_normals() || cloud.normals.size() == cloud.size(),
          "DeviceCloud::from_host: normals and points differ in count");
  require(!cloud.has_colors() || cloud.colors.size() == cloud.size(),
          "DeviceCloud::from_host: colours and points differ in count");
  std::vector<Point4f> points(cloud.size()), normals(cloud.normals.size());
  for (std::size_t i = 0; i < points.size(); ++i) points[i] << cloud.points[i], 1.0f;
  for (std::size_t i = 0; i < normals.size(); ++i) normals[i] << cloud.normals[i], 0.0f;
  std::vector<std::uint32_t> colors(cloud.colors.size());
  for (std::size_t i = 0; i < colors.size(); ++i) colors[i] = pack_rgb(cloud.colors[i]);
  DeviceCloud out;
  out.points = compute::Buffer<Point4f>::from_host(context, points);
  if (!normals.empty()) out.normals = compute::Buffer<Point4f>::from_host(context, normals);
  if (!colors.empty()) out.colors = compute::Buffer<std::uint32_t>::from_host(context, colors);
  return out;
}

PointCloud DeviceCloud::to_host() const {
  const std::vector<Point4f> host_points = points.to_vector();
  const std::vector<Point4f> host_normals = normals.to_vector();
  const std::vector<std::uint32_t> host_colors = colors.to_vector();
  PointCloud cloud;
  for (std::size_t i = 0; i < host_points.size(); ++i) {
    if (!is_valid(host_points[i])) continue;
    cloud.points.push_back(host_points[i].head<3>());
    if (has_normals()) cloud.normals.push_back(host_normals[i].head<3>());
    if (has_colors()) cloud.colors.push_back(unpack_rgb(host_colors[i]));
  }
  return cloud;
}

DeviceCloud subsample(const compute::Context& context, const DeviceCloud& cloud, int k) {
  cloud.validate("subsample");
  require(k >= 1, "subsample: k must be >= 1, got " + std::to_string(k));
  const std::size_t stride = static_cast<std::size_t>(k);
  const std::size_t count = (cloud.size() + stride - 1) / stride;
  DeviceCloud out;
  out.points = compute::Buffer<Point4f>(context, count);
  if (cloud.has_normals()) out.normals = compute::Buffer<Point4f>(context, count);
  if (cloud.has_colors()) out.colors = compute::Buffer<std::uint32_t>(context, count);
  if (count == 0) return out;
  const auto optional = [](const auto& buffer) {
    return buffer.empty() ? compute::BufferArg() : compute::BufferArg(buffer);
  };
  compute::dispatch(
      context, kSubsampleKernel,
      {cloud.points, optional(cloud.normals), optional(cloud.colors), out.points,
       optional(out.normals), optional(out.colors)},
      kernels::SubsampleParams{static_cast<std::uint32_t>(count), static_cast<std::uint32_t>(k),
                               cloud.has_normals() ? 1u : 0u, cloud.has_colors() ? 1u : 0u},
      {compute::groups_for(count, kSubsampleKernel.local_x), 1});
  return out;
}

}  // namespace kartograf::geometry
