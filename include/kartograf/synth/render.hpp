#pragma once
// Rendering RGB-D frames of the synthetic world with exact ground truth and a Kinect-v1-like
// depth noise model.
//
// Camera: the TUM optical frame (x right, y down, z forward); pixel (u, v) looks along
// ((u - cx) / fx, (v - cy) / fy, 1), sampled at the pixel's integer coordinates, so that the
// back-projection of core/intrinsics.hpp inverts it exactly. Depth is TUM-scaled (5000 units per
// metre, 0 = no return). Colour is albedo x view-independent shading (synth/material.hpp), so a
// surface keeps its brightness from every view.
//
// Ground truth (plane_id, semantic, depth_metres) describes the exact scene at each pixel's centre,
// with no noise and no dropouts: mask it with depth > 0 to compare with the sensor's view.
//
// Noise is keyed by (frame_seed, pixel): a frame renders identically on any number of threads,
// and frames can be rendered in any order.
#include <cstdint>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::synth {

inline constexpr double kTumDepthUnitsPerMetre = 5000.0;

// Kinect v1 depth errors; each part can be switched off. References: C. V. Nguyen, S. Izadi,
// D. Lovell, "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and Tracking", 3DIMPVT
// 2012 (axial and lateral noise); K. Khoshelham, S. O. Elberink, "Accuracy and Resolution of
// Kinect Depth Data for Indoor Mapping Applications", Sensors 2012 (disparity quantization).
struct NoiseModel {
  // Axial: z += N(0, sigma_z), th = angle between the ray and the surface normal,
  //   sigma_z = a + b (z - c)^2  [+ 0.0001 / sqrt(z) * th^2 / (pi/2 - th)^2 with the angle term].
  bool axial = true;
  double axial_a = 0.0012, axial_b = 0.0019, axial_c = 0.4;
  bool axial_angle_term = true;
  // Lateral: depth edges move. Each pixel measures the surface seen by the pixel displaced by
  // N(0, sigma_L) pixels per axis (rounded, at most 3), intersected with its own ray; inside a
  // plane nothing changes. sigma_L = lateral_px + 0.035 th / (pi/2 - th) (th capped at 85 deg).
  bool lateral = true;
  double lateral_px = 0.8;
  // Quantization of the disparity d = fx * baseline / z to 1/subpixel pixel:
  // depth steps dz ~ z^2 / (fx * baseline * subpixel).
  bool quantization = true;
  double baseline = 0.075;
  int subpixel = 8;
  // No return closer than min_range or beyond max_range (metres, after the noise).
  double min_range = 0.4;
  double max_range = 4.5;
  // No return at grazing incidence: probability rising linearly from 0 at grazing_start_deg to 1
  // at grazing_limit_deg.
  bool grazing_dropout = true;
  double grazing_start_deg = 70.0, grazing_limit_deg = 78.0;
  // No return on dark surfaces: probability 1 - albedo / dark_albedo (albedo: luminance, 0..1).
  bool dark_dropout = true;
  double dark_albedo = 0.1;
  // Flying pixels: a pixel next to a depth jump of more than flying_min_jump metres becomes, with
  // probability flying_fraction, a mix fore + w (back - fore) with w uniform in (0, 1).
  bool flying_pixels = true;
  double flying_fraction = 0.5;
  double flying_min_jump = 0.1;
  // Colour sensor noise: N(0, color_sigma) per channel, in 8-bit levels.
  bool color_noise = true;
  double color_sigma = 2.0;

  static NoiseModel kinect() { return {}; }
  // Exact depth (rounded to 1/5000 m), every return, clean colour.
  static NoiseModel none();

  // Axial standard deviation [m] at depth z [m] and incidence angle theta [rad].
  double axial_sigma(double z, double theta) const;
  // Throws Error naming the first out-of-range field.
  void validate() const;
};

struct SyntheticFrame {
  RgbImage color;
  DepthImage depth;           // 5000 units per metre, 0 = no return
  LabelImage plane_id;        // ground truth: World::planes id, 0 = nothing
  SemanticImage semantic;     // ground truth
  Image<float> depth_metres;  // ground truth: exact z [m], NaN where the ray hits nothing
};

struct RenderParams {
  int threads = 0;  // 0: std::thread::hardware_concurrency()
};

// One frame seen by a camera at camera_to_world (TUM optical frame), inside the building.
// Visibility comes from rasterizing the world's plane polygons with a depth buffer, each pixel's
// depth from intersecting its ray with the winning plane: exactly what ray casting the world gives
// (the tests compare with RayCaster), with a visibility pass ten times cheaper.
SyntheticFrame render(const World& world, const PinholeIntrinsics& intrinsics,
                      const Eigen::Isometry3d& camera_to_world, const NoiseModel& noise,
                      std::uint64_t frame_seed, const RenderParams& options = {});

}  // namespace kartograf::synth
