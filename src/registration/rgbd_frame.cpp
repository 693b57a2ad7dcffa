#include "kartograf/registration/rgbd_frame.hpp"

#include <string>

namespace kartograf::registration {

namespace {

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

int pyramid_level_at_most(int width, int max_width) {
  require(width > 0 && max_width > 0, "pyramid_level_at_most: widths must be positive");
  int level = 0;
  while ((width >> level) > max_width) ++level;
  return level;
}

RgbdPyramidBuilder::RgbdPyramidBuilder(const compute::Context& context,
                                       const PinholeIntrinsics& camera,
                                       const geometry::DepthRange& range)
    : projector_(context, camera, range), depth_(context, camera.width, camera.height) {}

void RgbdPyramidBuilder::build(const DepthImage& depth, const RgbImage* color,
                               FramePyramid& pyramid) {
  const PinholeIntrinsics& k = camera();
  require(depth.width() == k.width && depth.height() == k.height,
          "RGB-D frame: depth image is " + size_text(depth.width(), depth.height()) +
              ", the camera is " + size_text(k.width, k.height));
  depth_.upload(depth);
  if (pyramid.params().with_colors) {
    require(color && !color->empty(),
            "RGB-D frame: colour is required (colour-gated ICP) but the "
            "frame has none");
    require(color->width() == k.width && color->height() == k.height,
            "RGB-D frame: colour image is " + size_text(color->width(), color->height()) +
                ", the depth camera is " + size_text(k.width, k.height));
    if (packed_colors_.empty()) packed_colors_ = Image<std::uint32_t>(k.width, k.height);
    const auto source = color->pixels();
    const auto target = packed_colors_.pixels();
    for (std::size_t i = 0; i < source.size(); ++i) target[i] = pack_rgb(source[i]);
    pyramid.base_colors().upload(packed_colors_);
  }
  pyramid.build(projector_, depth_);
}

}  // namespace kartograf::registration
