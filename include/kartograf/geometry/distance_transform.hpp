#pragma once
// The exact Euclidean distance transform of a 2-D mask, without OpenCV: what
// cv::distanceTransform(DIST_L2, DIST_MASK_PRECISE) computes, so that code in the compute core
// (the rooms laser scanner's sphere tracing) can have it.
#include <cstdint>

#include "kartograf/core/image.hpp"

namespace kartograf::geometry {

// The squared distance in pixels from every pixel to the nearest zero pixel of `mask` (0 on zero
// pixels), or -1 everywhere when the mask has no zero pixel. Integers, so exact: the separable
// lower-envelope algorithm of Felzenszwalb and Huttenlocher (2012) in integer arithmetic.
Image<std::int64_t> squared_distance_to_zero(const Image<std::uint8_t>& mask);

// The same as distances: sqrt of the squared distance in float (exact below 2^24 squared pixels),
// infinity where there is no zero pixel.
Image<float> distance_to_zero(const Image<std::uint8_t>& mask);

}  // namespace kartograf::geometry
