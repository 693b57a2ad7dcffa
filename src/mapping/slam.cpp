#include "kartograf/mapping/slam.hpp"

#include <chrono>
#include <functional>
#include <optional>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/core/pose.hpp"
#include "kartograf/mapping/online_slam.hpp"

namespace kartograf::mapping {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

registration::OdometryParams with_source_units(registration::OdometryParams params,
                                               const FrameSource& source) {
  params.depth_range.units_per_metre = source.depth_units_per_metre();
  return params;
}

const RgbImage* color_of(const registration::RgbdImages& images) {
  return images.color.empty() ? nullptr : &images.color;
}

void report_progress(const SlamObserver& observer, std::string_view stage, std::size_t done,
                     std::size_t total) {
  if (observer.on_progress) observer.on_progress(stage, done, total);
}

// The colour of each pyramid pixel: the top-left pixel of its 2^level x 2^level block (the
// pyramid averages depth; colour from an unregistered camera is only approximately aligned anyway).
void colors_at_level(const RgbImage& color, int level, int width, int height, RgbImage& out) {
  // The frame source checks colour against depth; a source that does not must not read past
  // the colour image.
  require(width > 0 && height > 0 && ((width - 1) << level) < color.width() &&
              ((height - 1) << level) < color.height(),
          "colour image is " + std::to_string(color.width()) + "x" +
              std::to_string(color.height()) + ", smaller than the depth camera's pixel grid (" +
              std::to_string(width << level) + "x" + std::to_string(height << level) + ")");
  if (out.width() != width || out.height() != height) out = RgbImage(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) out(u, v) = color(u << level, v << level);
  }
}

// Second pass: every frame's points and normals at its pose (pose_of(i, images); a pose given
// with the frames is resolved while they are read).
PointCloud fuse_map(
    const compute::Context& context, const FrameSource& source, std::size_t frames,
    const std::function<Eigen::Isometry3d(std::size_t, const registration::RgbdImages&)>& pose_of,
    const SlamParams& params, const SlamObserver& observer, SlamResult& result) {
  const registration::OdometryParams odometry = with_source_units(params.odometry, source);
  registration::RgbdPyramidBuilder builder(context, source.camera(), odometry.depth_range);
  // The level at most 320 pixels wide (half resolution of 640x480): averaged points with
  // smoother normals, a quarter of the work.
  const int level = registration::pyramid_level_at_most(source.camera().width, 320);
  registration::PyramidParams pyramid;
  pyramid.levels = level + 1;
  pyramid.first_normals_level = level;
  registration::FramePyramid frame(context, source.camera(), pyramid);
  MapFusion fusion(params.map);
  RgbImage level_colors;
  double fusing = 0;
  const FrameLoopTiming timing =
      for_each_frame(source, 0, frames, [&](std::size_t i, registration::RgbdImages& images) {
        const Eigen::Isometry3d pose = pose_of(i, images);
        const auto start = Clock::now();
        builder.build(images.depth, nullptr, frame);
        const registration::PyramidLevel& fused = frame.level(level);
        const PointImage points = fused.points.to_image();
        const NormalImage normals = fused.normals.to_image();
        const RgbImage* color = color_of(images);
        if (color) colors_at_level(*color, level, points.width(), points.height(), level_colors);
        fusion.add(points, normals, color ? &level_colors : nullptr, pose);
        fusing += seconds_since(start);
        report_progress(observer, "map", i + 1, frames);
      });
  result.timing.map_seconds = fusing;
  result.timing.load_seconds += timing.load_seconds;
  result.map_voxels = fusion.voxel_count();
  return fusion.cloud();
}

}  // namespace

PoseGraphParams slam_graph_options() {
  PoseGraphParams options;
  options.loop_closure_kernel = 0;
  options.prune_chi2 = 0;
  return options;
}

SlamResult run_slam(const compute::Context& context, const FrameSource& source,
                    const SlamParams& params, const SlamObserver& observer) {
  const auto start = Clock::now();
  OnlineSlam slam(context, source.camera(), source.depth_units_per_metre(), params, observer);
  const std::size_t total = source.size();
  const FrameLoopTiming timing =
      for_each_frame(source, 0, total, [&](std::size_t i, registration::RgbdImages& images) {
        slam.add(images);
        report_progress(observer, "odometry", i + 1, total);
      });
  SlamResult result = slam.finish();
  result.odometry.timing = timing;
  result.timing.load_seconds = timing.load_seconds;
  if (params.build_map && total > 0) {
    const auto optimised = [&](std::size_t i, const registration::RgbdImages&) {
      return result.poses[i];
    };
    result.map = fuse_map(context, source, total, optimised, params, observer, result);
  }
  result.timing.total_seconds = seconds_since(start);
  return result;
}

SlamResult run_with_known_poses(const compute::Context& context, const FrameSource& source,
                                const KnownPoseLookup& pose_of, const SlamParams& params,
                                const SlamObserver& observer) {
  require(static_cast<bool>(pose_of), "slam with known poses: no pose lookup given");
  const auto start = Clock::now();
  SlamResult result;
  result.poses_given = true;
  std::optional<Eigen::Isometry3d> first_inverse;
  // Expressed relative to the first frame, as estimated trajectories are.
  const auto relative_pose = [&](std::size_t i, const registration::RgbdImages& images) {
    const Eigen::Isometry3d pose = pose_of(i, images);
    require(is_rigid(pose), "slam with known poses: the pose of frame " + std::to_string(i) +
                                " is not finite or not a rotation");
    if (!first_inverse) first_inverse = pose.inverse();
    const Eigen::Isometry3d relative = *first_inverse * pose;
    result.poses.push_back(relative);
    result.odometry.timestamps.push_back(images.timestamp);
    return relative;
  };
  if (params.build_map) {
    result.map = fuse_map(context, source, source.size(), relative_pose, params, observer, result);
  } else {
    result.timing.load_seconds =
        for_each_frame(source, 0, source.size(), [&](std::size_t i, registration::RgbdImages& im) {
          relative_pose(i, im);
        }).load_seconds;
  }
  result.odometry.poses = result.poses;
  result.timing.total_seconds = seconds_since(start);
  return result;
}

}  // namespace kartograf::mapping
