#include "kartograf/registration/frame_pyramid.hpp"

#include <cmath>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kernels/pyramid_downsample/pyramid_downsample.h"

namespace kartograf::registration {

namespace {

constexpr compute::KernelSpec kDownsampleKernel{"pyramid_downsample", KG_PYRAMID_DOWNSAMPLE_LOCAL_X,
                                                KG_PYRAMID_DOWNSAMPLE_LOCAL_Y};
constexpr int kMinLevelSize = 8;

void downsample(const compute::Context& context, const PyramidLevel& fine, PyramidLevel& coarse,
                bool with_colors, float max_depth_jump) {
  const kernels::PyramidDownsampleParams params{static_cast<std::uint32_t>(fine.camera.width),
                                                static_cast<std::uint32_t>(coarse.camera.width),
                                                static_cast<std::uint32_t>(coarse.camera.height),
                                                with_colors ? 1u : 0u, max_depth_jump};
  const compute::BufferArg fine_colors =
      with_colors ? compute::BufferArg(fine.colors.buffer()) : compute::BufferArg();
  const compute::BufferArg coarse_colors =
      with_colors ? compute::BufferArg(coarse.colors.buffer()) : compute::BufferArg();
  compute::dispatch(context, kDownsampleKernel,
                    {fine.points.buffer(), fine_colors, coarse.points.buffer(), coarse_colors},
                    params,
                    {compute::groups_for(static_cast<std::size_t>(coarse.camera.width),
                                         kDownsampleKernel.local_x),
                     compute::groups_for(static_cast<std::size_t>(coarse.camera.height),
                                         kDownsampleKernel.local_y)});
}

}  // namespace

PinholeIntrinsics half_resolution(const PinholeIntrinsics& camera) {
  // Fine pixel centres 2x and 2x + 1 average to 2x + 0.5, which is coarse pixel x.
  return {camera.width / 2, camera.height / 2,     camera.fx / 2,
          camera.fy / 2,    (camera.cx - 0.5) / 2, (camera.cy - 0.5) / 2};
}

CloudView PyramidLevel::view() const {
  CloudView view;
  view.points = &points.buffer();
  view.normals = normals.size() ? &normals.buffer() : nullptr;
  view.colors = colors.size() ? &colors.buffer() : nullptr;
  view.camera = camera;
  return view;
}

FramePyramid::FramePyramid(const compute::Context& context, const PinholeIntrinsics& camera,
                           const PyramidParams& params)
    : context_(&context), params_(params) {
  camera.validate("frame pyramid camera");
  require(params.levels >= 1 && params.levels <= 16,
          "frame pyramid: levels must be 1..16, got " + std::to_string(params.levels));
  require(std::isfinite(params.max_depth_jump) && params.max_depth_jump > 0,
          "frame pyramid: max_depth_jump must be positive");
  require(params.first_normals_level >= 0 && params.first_normals_level < params.levels,
          "frame pyramid: first_normals_level must be 0.." + std::to_string(params.levels - 1) +
              ", got " + std::to_string(params.first_normals_level));
  PinholeIntrinsics level_camera = camera;
  for (int level = 0; level < params.levels; ++level) {
    if (level > 0) level_camera = half_resolution(level_camera);
    require(level_camera.width >= kMinLevelSize && level_camera.height >= kMinLevelSize,
            "frame pyramid: level " + std::to_string(level) + " of a " +
                std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                " camera would be " + std::to_string(level_camera.width) + "x" +
                std::to_string(level_camera.height) +
                ", under the minimum of 8x8 (use fewer levels)");
    PyramidLevel& added = levels_.emplace_back();
    added.camera = level_camera;
    added.points = compute::DeviceImage<Point4f>(context, level_camera.width, level_camera.height);
    if (level >= params.first_normals_level) {
      added.normals =
          compute::DeviceImage<Point4f>(context, level_camera.width, level_camera.height);
    }
    if (params.with_colors) {
      added.colors =
          compute::DeviceImage<std::uint32_t>(context, level_camera.width, level_camera.height);
    }
  }
}

compute::DeviceImage<std::uint32_t>& FramePyramid::base_colors() {
  require(params_.with_colors, "frame pyramid: made without colours (PyramidParams::with_colors)");
  return levels_[0].colors;
}

void FramePyramid::build() {
  const PinholeIntrinsics& base = levels_[0].camera;
  require(levels_[0].points.width() == base.width && levels_[0].points.height() == base.height,
          "frame pyramid: base_points() was resized away from the camera's " +
              std::to_string(base.width) + "x" + std::to_string(base.height));
  for (std::size_t level = 0; level < levels_.size(); ++level) {
    if (level > 0) {
      downsample(*context_, levels_[level - 1], levels_[level], params_.with_colors,
                 params_.max_depth_jump);
    }
    if (static_cast<int>(level) >= params_.first_normals_level) {
      geometry::estimate_normals(*context_, levels_[level].points, levels_[level].normals,
                                 params_.normals);
    }
  }
}

void FramePyramid::build(const geometry::DepthBackprojector& projector,
                         const compute::DeviceImage<std::uint16_t>& depth) {
  const PinholeIntrinsics& camera = projector.intrinsics();
  const PinholeIntrinsics& base = levels_[0].camera;
  require(camera == base, "frame pyramid: the back-projector's camera differs from the pyramid's");
  projector.run(depth, levels_[0].points);
  build();
}

std::vector<CloudView> FramePyramid::views() const {
  std::vector<CloudView> result;
  for (const PyramidLevel& level : levels_) result.push_back(level.view());
  return result;
}

FramePyramid make_frame_pyramid(const compute::Context& context, const PinholeIntrinsics& camera,
                                const PointImage& points, const Image<std::uint32_t>* colors,
                                PyramidParams params) {
  params.with_colors = colors != nullptr;
  FramePyramid pyramid(context, camera, params);
  pyramid.base_points().upload(points);
  if (colors) pyramid.base_colors().upload(*colors);
  pyramid.build();
  return pyramid;
}

}  // namespace kartograf::registration
