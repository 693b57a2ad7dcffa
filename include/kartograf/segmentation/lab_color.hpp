#pragma once
// CIE-Lab colour (D65 white, sRGB input): the colour space in which methods.md M1 step 2 grows
// regions, because Euclidean distance there roughly follows perceived colour difference.
#include <Eigen/Core>

#include "kartograf/core/color.hpp"
#include "kartograf/core/image.hpp"

namespace kartograf::segmentation {

using LabImage = Image<Eigen::Vector4f>;  // (L*, a*, b*, 0) per pixel, CIE-Lab D65

// One sRGB pixel (gamma-decoded, D65 white) to (L*, a*, b*); white -> (100, 0, 0).
Eigen::Vector3f rgb_to_lab(const Rgb8& rgb);

// Every pixel of an sRGB image to Lab (table-driven: a few ns per pixel).
LabImage to_lab(const RgbImage& rgb);

}  // namespace kartograf::segmentation
