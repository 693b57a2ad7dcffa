#pragma once
// The check's inputs: real 7-Scenes RedKitchen frames (the raw copies that
// kartograf_export_device_data writes; kartograf_gpu_check --data names the folder), the same
// frames enlarged to 1280x720, and random depth (never zeros: every pixel a valid depth, some
// holes).
#include <filesystem>
#include <string>
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::gpu_check {

struct RgbdFrame {
  DepthImage depth;  // millimetres
  RgbImage color;    // registered to the depth image's grid (same size)
};

struct FrameSet {
  std::string name;  // "7scenes", "7scenes-1280x720", "random"
  PinholeIntrinsics camera;
  std::vector<RgbdFrame> frames;
};

// The first `count` frames of DATA/7scenes_redkitchen/frames (frame-NNNNNN.depth.png.raw and
// .color.jpg.raw); throws Error naming a missing file.
FrameSet seven_scenes(const std::filesystem::path& data_dir, int count);

// The ipa room map office_e (DATA/ipa_room_maps/test_maps/office_e.png.raw), 5 cm cells: the
// laser-scan ray casting's input.
OccupancyGrid office_map(const std::filesystem::path& data_dir);

// Every frame scaled by nearest neighbour to width x height, the camera scaled with it.
FrameSet enlarged(const FrameSet& frames, int width, int height);

// `count` frames of uniformly random depth in [0.5, 4] m with 2% holes and random colours.
FrameSet random_frames(const PinholeIntrinsics& camera, int count, unsigned seed);

}  // namespace kartograf::gpu_check
