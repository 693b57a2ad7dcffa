#pragma once
// The demo's built-in input: a depth frame of an analytic room, ray cast without noise so that
// every pixel has an exact depth. Temporary: a synthetic world module will replace it.
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::demo {

struct DemoFrame {
  PinholeIntrinsics intrinsics;
  DepthImage depth;  // millimetres
};

// A 5 m x 4 m x 2.6 m room (floor, ceiling, four walls) with a 0.8 x 0.6 x 0.9 m cabinet, seen
// from 1.2 m height looking along the room's diagonal and 10 degrees down; 640x480, fx = fy = 525.
DemoFrame render_demo_room();

}  // namespace kartograf::demo
