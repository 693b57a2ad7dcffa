#pragma once
// CIE-Lab colour (D65 white, sRGB input): the colour space in which docs/methods.md M1 step 2 grows
// regions, because Euclidean distance there roughly follows perceived colour difference.
#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "kartograf/core/color.hpp"
#include "kartograf/core/image.hpp"

namespace kartograf::segmentation {

using LabImage = Image<Eigen::Vector4f>;  // (L*, a*, b*, 0) per pixel, CIE-Lab D65

// Lab as integers in 1/64 units, clamped to +-255 (sRGB colours stay within +-128), rounded half
// to even: exact integer arithmetic on every backend, 8 bytes a pixel. [3] is 1 for a valid
// colour, 0 for none (a NaN or infinite Lab value).
inline constexpr float kLabCodeScale = 64.0f;
using LabCode = std::array<std::int16_t, 4>;
using LabCodeImage = Image<LabCode>;

// One sRGB pixel (gamma-decoded, D65 white) to (L*, a*, b*); white -> (100, 0, 0).
Eigen::Vector3f rgb_to_lab(const Rgb8& rgb);

// Every pixel of an sRGB image to Lab (table-driven: a few ns per pixel).
LabImage to_lab(const RgbImage& rgb);

// The same conversion straight to codes (what the region growing reads); the second form reuses
// `codes` (resized when its size differs).
LabCodeImage to_lab_codes(const RgbImage& rgb);
void to_lab_codes(const RgbImage& rgb, LabCodeImage& codes);
LabCodeImage to_lab_codes(const LabImage& lab);

// A code back to Lab (exact: codes are multiples of 1/64).
inline Eigen::Vector3f lab_of(const LabCode& code) {
  return Eigen::Vector3f(code[0], code[1], code[2]) / kLabCodeScale;
}

}  // namespace kartograf::segmentation
