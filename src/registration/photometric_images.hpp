#pragma once
// A frame's images as the photometric refinement reads them (photometric_refinement.cpp): grey
// levels, their binomial smoothings with gradients, the pixels beside depth edges, and the
// textured pixels (samples) it compares. Private to the registration layer.
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::registration::detail {

using GreyImage = Image<float>;
using Mask = Image<std::uint8_t>;

GreyImage grey_of(const RgbImage& color);
// `passes` passes of the separable binomial filter [1 4 6 4 1] / 16, borders clamped.
GreyImage blurred(const GreyImage& grey, int passes);

// An image with its central-difference gradients, sampled bilinearly.
struct Textured {
  GreyImage value, dx, dy;

  explicit Textured(GreyImage image);
  // False outside the area where all three are defined.
  bool sample(double u, double v, double& i, double& gx, double& gy) const {
    if (!(u >= 1 && v >= 1 && u < value.width() - 2 && v < value.height() - 2)) return false;
    const int x = static_cast<int>(u), y = static_cast<int>(v);
    const double fx = u - x, fy = v - y;
    const auto lerp = [&](const GreyImage& image) {
      return (1 - fy) * ((1 - fx) * image(x, y) + fx * image(x + 1, y)) +
             fy * ((1 - fx) * image(x, y + 1) + fx * image(x + 1, y + 1));
    };
    i = lerp(value);
    gx = lerp(dx);
    gy = lerp(dy);
    return true;
  }
};

// Source pixels whose smoothed grey level mixes two surfaces apart in depth (a cabinet's edge
// against the wall behind it): as the camera moves the two slide apart, so their residuals pull
// the motion towards the parallax rather than the camera's motion. Only steps between pixels that
// both have depth count: a dark surface's dropouts or a range limit say nothing of depth. Their
// reach is the fine pass's (one binomial pass, 2 pixels, and the gradient's 1). The coarse pass
// keeps them, as its wide basin needs the edges' contrast, and the fine pass removes what they
// pull: masked to the coarse blur's reach of 6 pixels, survey seed 8's degenerate views kept too
// few textured pixels to refine; masked to 3 in both passes, seeds 5, 6 and 10 drifted more.
Mask near_depth_edges(const DepthImage& depth, double units_per_metre);

// A textured source pixel: its point and its smoothed grey level.
struct Sample {
  Eigen::Vector3d point;  // source camera frame
  double intensity = 0;
};

// What selects a frame's samples: the smoothing, whether the pixels beside depth edges are left
// out, the parameters that pick pixels and the camera that back-projects them.
struct SampleChoice {
  int passes = 1;
  bool masked = false;
  int pixel_step = 1;
  double min_gradient = 0, max_gradient = 0, max_depth = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  auto operator<=>(const SampleChoice&) const = default;
};

// What a PhotometricFrame derives from its images, each part made on first use.
struct PreparedImages {
  std::optional<GreyImage> grey;
  std::map<int, Textured> smoothed;  // by the number of binomial passes
  std::map<SampleChoice, std::vector<Sample>> samples;
  std::optional<Mask> near_depth_edges;
  std::optional<Mask> kept_all;  // no pixel left out
};

}  // namespace kartograf::registration::detail
