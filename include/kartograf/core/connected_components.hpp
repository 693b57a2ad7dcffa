#pragma once
// Connected regions of a binary mask as a label image: how ground-truth rooms are read from the
// ipa_room_segmentation maps, where each room is one connected white region.
#include <cstdint>

#include "kartograf/core/image.hpp"
#include "kartograf/core/label_image.hpp"

namespace kartograf {

enum class Connectivity { four, eight };

struct ComponentParams {
  Connectivity connectivity = Connectivity::four;
  int min_pixels = 1;  // smaller regions (specks) get label 0 and no number
};

// Every connected region of non-zero mask pixels gets a label 1..N, numbered in raster order of
// its first pixel (top row first, left to right). Throws Error if there are more than 65535.
LabelImage label_connected_components(const Image<std::uint8_t>& mask,
                                      const ComponentParams& options = {});

}  // namespace kartograf
