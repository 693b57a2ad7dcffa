#pragma once
// One RGB-D frame as host images, and its way onto the device: odometry, loop-closure
// verification and map fusion all turn host depth (and colour) into a FramePyramid, with the same
// depth range and the same packing of colours.
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/registration/frame_pyramid.hpp"

namespace kartograf::registration {

struct RgbdImages {
  DepthImage depth;      // raw depth units (see geometry::DepthRange), 0 = no measurement
  RgbImage color;        // the depth camera's pixel grid; empty when the source has no colour
  double timestamp = 0;  // seconds
  // The camera-to-world pose the data set gives with the frame (ground truth), if any: never
  // used to estimate, only to run on a known trajectory or to score.
  std::optional<Eigen::Isometry3d> ground_truth = std::nullopt;
  // The camera-to-world pose another sensor gives (a wheeled robot's odometry through its camera
  // mount), if any: the odometry predicts the step from it instead of its motion model
  // (RgbdOdometry::track), so a view that leaves a direction free takes the sensor's motion there.
  std::optional<Eigen::Isometry3d> motion_prior = std::nullopt;
};

// The first pyramid level (level l is about width / 2^l wide) at most max_width pixels wide: where
// ICP starts and where geometric information is read, whatever the camera's resolution.
int pyramid_level_at_most(int width, int max_width);

// Holds the back-projection tables and upload buffers of one camera: building a pyramid per frame
// allocates nothing.
class RgbdPyramidBuilder {
 public:
  // Throws Error on invalid intrinsics or range.
  RgbdPyramidBuilder(const compute::Context& context, const PinholeIntrinsics& camera,
                     const geometry::DepthRange& range);

  // Uploads depth (and the colours, when the pyramid keeps colours) and builds every level; only
  // dispatches. Throws Error when an image does not have the camera's size, or when the pyramid
  // keeps colours and `color` is null or empty.
  void build(const DepthImage& depth, const RgbImage* color, FramePyramid& pyramid);

  const PinholeIntrinsics& camera() const { return projector_.intrinsics(); }

 private:
  geometry::DepthBackprojector projector_;
  compute::DeviceImage<std::uint16_t> depth_;
  Image<std::uint32_t> packed_colors_;  // host staging, kept between frames
};

}  // namespace kartograf::registration
