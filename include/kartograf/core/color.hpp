#pragma once
// 8-bit colour pixels and images, as read from and written to image files (RGB order), and the
// packed 32-bit colour word that device buffers hold.
#include <array>
#include <cstdint>

#include "kartograf/core/image.hpp"

namespace kartograf {

using Rgb8 = std::array<std::uint8_t, 3>;
using RgbImage = Image<Rgb8>;
using GrayImage = Image<std::uint8_t>;

// One colour per 32-bit word, r | g << 8 | b << 16 (the top byte is unused): the layout of every
// colour buffer on a device (geometry::DeviceCloud, registration::CloudView and FramePyramid).
inline std::uint32_t pack_rgb(const Rgb8& c) {
  return std::uint32_t{c[0]} | std::uint32_t{c[1]} << 8 | std::uint32_t{c[2]} << 16;
}
inline Rgb8 unpack_rgb(std::uint32_t packed) {
  return {static_cast<std::uint8_t>(packed & 0xff), static_cast<std::uint8_t>((packed >> 8) & 0xff),
          static_cast<std::uint8_t>((packed >> 16) & 0xff)};
}

}  // namespace kartograf
