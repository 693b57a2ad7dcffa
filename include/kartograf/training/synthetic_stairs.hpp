#pragma once
// Training data made by the project, not part of the product library (target kartograf_training,
// above semantic and synth): synthetic training and test views for the Haar cascade (docs/methods.md M2 step 4): a room corner
// (floor, back wall, side walls, ceiling) with random furniture-like boxes and, optionally, a
// flight of 3-5 steps against the back wall, ray cast (synth::RayCaster) by a pinhole camera at a
// random place, height, yaw and pitch, with range noise; then the grey normals image
// (normals_image.hpp, absolute encoding). The ground-truth box is the square around the stairs'
// projected bounding box, the shape of a cascade window.
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/semantic/haar_cascade.hpp"

namespace kartograf::training {

struct StairsViewParams {
  int width = 320, height = 240;
  double focal = 250;          // pixels, fx = fy; principal point at the centre
  double range_noise = 0.004;  // metres at 1 m, growing with range^2 (Kinect-like)
  double max_range = 8;
  double min_distance = 2.0, max_distance = 5.0;  // camera to the stairs' front
  double max_yaw_deg = 35;  // of the view direction from the back wall's normal
};

struct StairsView {
  PointImage points;                // camera frame (x right, y down, z forward)
  GrayImage gray;                   // grey normals image
  std::optional<semantic::Detection> object;  // square ground-truth box; nullopt without stairs
  semantic::Detection tight;                  // the projected bounding box itself (valid when object is set)
  double stairs_width = 0, stairs_height = 0;  // metres
};

// One view, deterministic in seed. with_stairs false: the same kind of room without stairs.
// Throws Error on bad options.
StairsView render_stairs_view(const compute::Context& context, std::uint64_t seed, bool with_stairs,
                              const StairsViewParams& options = {});

// `count` window x window positives from a view with stairs, the paper's recipe: the ground-truth
// square shifted (+-5%), scaled (+-8%) and rotated (+-8 deg), with a "relit" grey mapping
// (gain 0.8..1.2, offset +-15, noise sigma 3). The first is the unperturbed square.
std::vector<GrayImage> stairs_positives(const StairsView& view, int count, int window,
                                        std::mt19937_64& rng);


}  // namespace kartograf::training
