#pragma once
// The normals image of method M2 (docs/methods.md M2 step 1): the normal of every pixel of an
// organized point image (an RGB-D frame back-projected, or an organized laser scan) stored as an
// RGB raster, one colour channel per normal component.
//
// Normals come from geometry::estimate_normals, so they run on every backend. Two things make the
// same call work for laser scans, whose frame has z up rather than z along the view:
//  - the points are first smoothed by a mean over an organized window that only takes neighbours
//    whose range (distance to the sensor at the origin) is within a limit of the centre's: a
//    plane stays the same plane under averaging, while Kinect disparity steps and laser range
//    noise (centimetres over pixels of millimetres) no longer dominate 4-neighbour tangents. The
//    limit is max_relative_range_jump x range or noise_sigmas x the sensor's range noise at that
//    range, whichever is larger; the noise is measured on the image itself (estimate_range_noise),
//    so a laser's 1 cm keeps a door leaf's 5 cm step apart while a Kinect's 3 cm at 4 m does not
//    break a far wall into pieces;
//  - estimate_normals' depth-jump test is relative to z, meaningless for z-up frames, so it is
//    given the points shifted to z >= 1 (a translation: tangents and normals are unchanged) with
//    the test switched off; depth edges were already respected by the smoothing, and the region
//    growing (regions.hpp) tests range jumps itself. The normals are then turned to face the
//    sensor at the origin (n . p <= 0).
#include <cstdint>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::semantic {

struct NormalsImageParams {
  int smoothing_radius = 5;               // window (2r + 1)^2; 0: no smoothing
  float max_relative_range_jump = 0.02f;  // neighbours farther apart in range are another surface
  float noise_sigmas = 4.0f;              // ... unless within this many noise sigmas; 0: off
};

// The range noise of an organized point image by range: in bins of bin_width metres, the robust
// standard deviation (1.4826 x median absolute value / sqrt 6) of the second differences of range
// along rows and columns, which cancel on smooth surfaces and are 6 sigma^2 in variance for
// independent noise. Bins with fewer than min_samples take the nearest populated bin's value.
struct RangeNoiseProfile {
  double bin_width = 0.25;        // m
  std::vector<double> sigma;      // per bin; empty when no bin had enough samples
  double at(double range) const;  // 0 when empty
};

RangeNoiseProfile estimate_range_noise(const PointImage& points, double bin_width = 0.25,
                                       int min_samples = 100);

// The organized mean filter described above; invalid pixels stay invalid.
PointImage smooth_organized_points(const PointImage& points, const NormalsImageParams& params);
// The same with the range noise already measured (estimate_range_noise of the same points), for
// callers that smooth one image with several windows.
PointImage smooth_organized_points(const PointImage& points, const NormalsImageParams& params,
                                   const RangeNoiseProfile& noise);

// Smoothing, then geometry::estimate_normals on `context`, normals facing the sensor (origin).
NormalImage estimate_organized_normals(const compute::Context& context, const PointImage& points,
                                       const NormalsImageParams& params = {});

enum class NormalEncoding : std::uint8_t {
  absolute,  // the paper's variant: (|nx|, |ny|, |nz|) * 255, opposite faces share a colour
  signed_,   // (n + 1) / 2 * 255: every direction its own colour
};

// Invalid normals become black. Components are rounded to the nearest level.
RgbImage normals_to_rgb(const NormalImage& normals, NormalEncoding encoding);

// Grey (ITU-R BT.601 luma, rounded) of an encoded normals image: the input of cascade detection
// (docs/methods.md M2 step 4).
GrayImage normals_rgb_to_gray(const RgbImage& normals_rgb);

}  // namespace kartograf::semantic
