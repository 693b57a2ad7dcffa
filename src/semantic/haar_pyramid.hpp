#pragma once
// The image pyramid the Haar detector scans, shared by detection and the mining of negatives in
// training, so that both see windows made the same way (area-averaged resizing).
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/semantic/haar_cascade.hpp"

namespace kartograf::semantic {

struct PyramidLevel {
  double scale = 1;  // image pixels per level pixel
  GrayImage image;
  IntegralImage integral;
};

// Levels whose window (cascade window) covers params.min_size .. max_size image pixels, growing by
// params.scale_factor. Throws Error on bad parameters.
std::vector<PyramidLevel> build_pyramid(const GrayImage& image, int window,
                                        const DetectionParams& params);

// The side x side square of `image` at (x, y), which must lie inside it.
GrayImage crop(const GrayImage& image, int x, int y, int side);

}  // namespace kartograf::semantic
