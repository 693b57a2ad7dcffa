#include "photometric_images.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace kartograf::registration::detail {

namespace {

// One pass of the separable binomial filter [1 4 6 4 1] / 16, borders clamped.
void blur(GreyImage& image) {
  const int w = image.width(), h = image.height();
  const float k[5] = {1 / 16.0f, 4 / 16.0f, 6 / 16.0f, 4 / 16.0f, 1 / 16.0f};
  GreyImage tmp(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      for (int d = -2; d <= 2; ++d) sum += k[d + 2] * image(std::clamp(x + d, 0, w - 1), y);
      tmp(x, y) = sum;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      for (int d = -2; d <= 2; ++d) sum += k[d + 2] * tmp(x, std::clamp(y + d, 0, h - 1));
      image(x, y) = sum;
    }
  }
}

// Depth steps between neighbouring pixels larger than this are surfaces apart, not one surface
// seen at a grazing angle (a floor 4 m away steps about 3 cm a pixel at 640x480).
constexpr double kEdgeJumpFraction = 0.03;
constexpr double kEdgeJumpMetres = 0.01;

// Set wherever a set pixel lies within `radius` (a square window), in two separable passes.
Mask dilated(const Mask& mask, int radius) {
  const int w = mask.width(), h = mask.height();
  const auto pass = [&](const Mask& in, bool along_rows) {
    Mask out(w, h, 0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!in(x, y)) continue;
        for (int d = -radius; d <= radius; ++d) {
          const int u = along_rows ? x + d : x, v = along_rows ? y : y + d;
          if (u >= 0 && u < w && v >= 0 && v < h) out(u, v) = 1;
        }
      }
    }
    return out;
  };
  return pass(pass(mask, true), false);
}

}  // namespace

GreyImage grey_of(const RgbImage& color) {
  GreyImage grey(color.width(), color.height());
  const auto in = color.pixels();
  const auto out = grey.pixels();
  for (std::size_t i = 0; i < in.size(); ++i) {
    out[i] = (static_cast<float>(in[i][0]) + static_cast<float>(in[i][1]) +
              static_cast<float>(in[i][2])) /
             3.0f;
  }
  return grey;
}

GreyImage blurred(const GreyImage& grey, int passes) {
  GreyImage result = grey;
  for (int i = 0; i < passes; ++i) blur(result);
  return result;
}

Textured::Textured(GreyImage image) : value(std::move(image)) {
  const int w = value.width(), h = value.height();
  dx = GreyImage(w, h, 0.0f);
  dy = GreyImage(w, h, 0.0f);
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      dx(x, y) = 0.5f * (value(x + 1, y) - value(x - 1, y));
      dy(x, y) = 0.5f * (value(x, y + 1) - value(x, y - 1));
    }
  }
}

Mask near_depth_edges(const DepthImage& depth, double units_per_metre) {
  const int w = depth.width(), h = depth.height();
  Mask edge(w, h, 0);
  const auto apart = [&](int x0, int y0, int x1, int y1) {
    const double a = depth(x0, y0) / units_per_metre, b = depth(x1, y1) / units_per_metre;
    return depth(x0, y0) != 0 && depth(x1, y1) != 0 &&
           std::abs(a - b) > kEdgeJumpFraction * std::min(a, b) + kEdgeJumpMetres;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (x + 1 < w && apart(x, y, x + 1, y)) edge(x, y) = edge(x + 1, y) = 1;
      if (y + 1 < h && apart(x, y, x, y + 1)) edge(x, y) = edge(x, y + 1) = 1;
    }
  }
  constexpr int kFinePassReach = 3;
  return dilated(edge, kFinePassReach);
}

}  // namespace kartograf::registration::detail
