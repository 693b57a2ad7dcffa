#pragma once
// 8-bit colour pixels and images, as read from and written to image files (RGB order).
#include <array>
#include <cstdint>

#include "kartograf/core/image.hpp"

namespace kartograf {

using Rgb8 = std::array<std::uint8_t, 3>;
using RgbImage = Image<Rgb8>;
using GrayImage = Image<std::uint8_t>;

}  // namespace kartograf
