#pragma once
// Pinhole camera intrinsics (no distortion): pixel (u, v) with depth z maps to
// ((u - cx) z / fx, (v - cy) z / fy, z) in the camera frame (x right, y down, z forward).
#include <cmath>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf {

struct PinholeIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;

  bool operator==(const PinholeIntrinsics&) const = default;

  // Throws Error naming `what` when the intrinsics cannot describe a camera.
  void validate(const std::string& what) const {
    require(width > 0 && height > 0, what + ": image size must be positive, got " +
                                         std::to_string(width) + "x" + std::to_string(height));
    require(std::isfinite(fx) && std::isfinite(fy) && fx > 0 && fy > 0,
            what + ": focal lengths must be finite and positive");
    require(std::isfinite(cx) && std::isfinite(cy), what + ": principal point must be finite");
  }

  // 7-Scenes and most Kinect v1 data sets: fx = fy = 585, centre (320, 240).
  static PinholeIntrinsics kinect_7scenes() { return {640, 480, 585.0, 585.0, 320.0, 240.0}; }
};

}  // namespace kartograf
