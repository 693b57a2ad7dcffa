#pragma once
// ICP's finest pair gate from the depth camera's noise. A structured-light camera's axial noise
// grows as the square of the depth (sigma_z = a + b (z - c)^2: C. V. Nguyen, S. Izadi, D. Lovell,
// "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and Tracking", 3DIMPVT 2012; the
// synthetic camera's noise too, synth/render.hpp): 1.5 mm at 1 m, 5.5 mm at 2 m, 1.8 cm at 3.4 m.
// A fixed gate of 3 cm keeps the pairs of a room seen from 1-2.5 m and drops those of a deeper
// one where the noise alone moves them apart: on SUN3D's study room (median depth 3.3-3.6 m) the
// odometry paired about half of each frame's points and drifted 7 cm in five frames. So the gate
// is `sigmas` times the noise at the frame's median depth where that is wider than the fixed one,
// on views that are not degenerate (RgbdOdometry; docs/slam.md, "The gate from the depth noise").
#include <cstdint>

#include "kartograf/core/point_image.hpp"

namespace kartograf::registration {

struct DepthNoiseGateParams {
  double sigmas = 3;                       // 0: the fixed gate always
  double a = 0.0012, b = 0.0019, c = 0.4;  // metres, metres per square metre, metres
  int stride = 16;                         // every stride-th pixel counts towards the median

  double sigma_at(double z) const { return a + b * (z - c) * (z - c); }
  // Throws Error unless sigmas, a, b are finite and >= 0, c finite and stride >= 1.
  void validate() const;
};

// The median depth in metres of the valid pixels (raw value > 0) among every stride-th; 0 when
// there are none.
double median_depth_m(const DepthImage& depth, double units_per_metre, int stride);

// max(fixed_gate_m, sigmas x sigma_at(median_depth_m)); fixed_gate_m without a median (0).
double depth_noise_gate(double fixed_gate_m, double median_depth_m,
                        const DepthNoiseGateParams& params);

}  // namespace kartograf::registration
