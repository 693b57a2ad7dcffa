#include "inputs.hpp"

#include <cstdio>
#include <random>

#include "raw_image_file.hpp"

namespace kartograf::gpu_check {

FrameSet seven_scenes(const std::filesystem::path& data_dir, int count) {
  FrameSet set;
  set.name = "7scenes";
  set.camera = PinholeIntrinsics::kinect_7scenes();
  const std::filesystem::path frames = data_dir / "7scenes_redkitchen" / "frames";
  for (int i = 0; i < count; ++i) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "frame-%06d", i);
    RgbdFrame frame;
    frame.depth = testing::raw::read_depth(frames / (std::string(stem) + ".depth.png.raw"));
    frame.color = testing::raw::read_color(frames / (std::string(stem) + ".color.jpg.raw"));
    set.frames.push_back(std::move(frame));
  }
  return set;
}

OccupancyGrid office_map(const std::filesystem::path& data_dir) {
  OccupancyGrid map;
  map.cells =
      testing::raw::read_occupancy(data_dir / "ipa_room_maps" / "test_maps" / "office_e.png.raw");
  map.resolution = 0.05;
  return map;
}

namespace {
template <class Pixel>
Image<Pixel> nearest(const Image<Pixel>& image, int width, int height) {
  Image<Pixel> result(width, height);
  for (int v = 0; v < height; ++v) {
    const int source_v = v * image.height() / height;
    for (int u = 0; u < width; ++u) result(u, v) = image(u * image.width() / width, source_v);
  }
  return result;
}
}  // namespace

FrameSet enlarged(const FrameSet& frames, int width, int height) {
  FrameSet set;
  set.name = frames.name + "-" + std::to_string(width) + "x" + std::to_string(height);
  const PinholeIntrinsics& k = frames.camera;
  const double sx = static_cast<double>(width) / k.width,
               sy = static_cast<double>(height) / k.height;
  set.camera = {width, height, k.fx * sx, k.fy * sy, k.cx * sx, k.cy * sy};
  for (const RgbdFrame& frame : frames.frames) {
    set.frames.push_back(
        {nearest(frame.depth, width, height), nearest(frame.color, width, height)});
  }
  return set;
}

FrameSet random_frames(const PinholeIntrinsics& camera, int count, unsigned seed) {
  FrameSet set;
  set.name = "random";
  set.camera = camera;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> depth_mm(500, 4000), byte(0, 255);
  std::bernoulli_distribution hole(0.02);
  for (int i = 0; i < count; ++i) {
    RgbdFrame frame{DepthImage(camera.width, camera.height), RgbImage(camera.width, camera.height)};
    for (std::size_t p = 0; p < frame.depth.size(); ++p) {
      frame.depth.data()[p] = hole(rng) ? 0 : static_cast<std::uint16_t>(depth_mm(rng));
      frame.color.data()[p] = {static_cast<std::uint8_t>(byte(rng)),
                               static_cast<std::uint8_t>(byte(rng)),
                               static_cast<std::uint8_t>(byte(rng))};
    }
    set.frames.push_back(std::move(frame));
  }
  return set;
}

}  // namespace kartograf::gpu_check
