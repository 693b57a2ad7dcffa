#include "photometric_images.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace kartograf::registration::detail {

namespace {

// The five taps of the binomial filter [1 4 6 4 1] / 16 summed in order, as every pass sums them.
float binomial(float a, float b, float c, float d, float e) {
  constexpr float k[5] = {1 / 16.0f, 4 / 16.0f, 6 / 16.0f, 4 / 16.0f, 1 / 16.0f};
  float sum = 0;
  sum += k[0] * a;
  sum += k[1] * b;
  sum += k[2] * c;
  sum += k[3] * d;
  sum += k[4] * e;
  return sum;
}

// One pass of the separable binomial filter, borders clamped. The clamping is confined to the
// first and last two columns, so the loops over a row's pixels vectorize (the same sums).
void blur(GreyImage& image) {
  const int w = image.width(), h = image.height();
  GreyImage tmp(w, h);
  const int inner_begin = std::min(2, w), inner_end = std::max(inner_begin, w - 2);
  for (int y = 0; y < h; ++y) {
    const float* in = image.data() + static_cast<std::size_t>(y) * w;
    float* out = tmp.data() + static_cast<std::size_t>(y) * w;
    const auto clamped = [&](int x) {
      const auto at = [&](int d) { return in[std::clamp(x + d, 0, w - 1)]; };
      return binomial(at(-2), at(-1), at(0), at(1), at(2));
    };
    for (int x = 0; x < inner_begin; ++x) out[x] = clamped(x);
    for (int x = inner_begin; x < inner_end; ++x) {
      out[x] = binomial(in[x - 2], in[x - 1], in[x], in[x + 1], in[x + 2]);
    }
    for (int x = inner_end; x < w; ++x) out[x] = clamped(x);
  }
  for (int y = 0; y < h; ++y) {
    const auto row = [&](int d) {
      return tmp.data() + static_cast<std::size_t>(std::clamp(y + d, 0, h - 1)) * w;
    };
    const float *r0 = row(-2), *r1 = row(-1), *r2 = row(0), *r3 = row(1), *r4 = row(2);
    float* out = image.data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) out[x] = binomial(r0[x], r1[x], r2[x], r3[x], r4[x]);
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
