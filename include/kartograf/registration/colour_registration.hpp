#pragma once
// Whether a camera's colour is registered to its depth (each colour pixel shows the surface the
// depth pixel measured), judged from the images themselves. Most RGB-D drivers register the two
// (TUM, SUN3D, the synthetic camera); 7-Scenes does not: its colour camera has another focal length
// and position, and colour edges lie 5-12 pixels away from the depth edges they belong to. The
// odometry lets the images measure a view's motion together with the geometry only where they are
// registered (OdometryParams::photometric_deep_views).
//
// The test: across every step in depth between two neighbouring pixels (more than depth_step x the
// nearer depth), the grey level's gradient magnitude is summed at each offset -kReach..kReach along
// the step's axis. Registered colour has an edge where the depth has one, so the sum peaks at
// offset 0; unregistered colour spreads it. The contrast is the sum at 0 over the mean at offsets
// 4..kReach either side: 1.6-2.0 on the SUN3D fragment and the synthetic surveys, 0.8-1.2 on
// 7-Scenes, over a few frames (docs/slam.md, "Deep views measured with the images").
#include <array>
#include <cstdint>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::registration {

enum class ColourRegistration { undecided, registered, not_registered };

const char* to_string(ColourRegistration verdict);

struct ColourRegistrationParams {
  double depth_step = 0.05;             // a step in depth: over this fraction of the nearer depth
  double registered_contrast = 1.35;    // at or above: registered
  double unregistered_contrast = 1.15;  // below: not registered
  std::uint64_t min_steps = 10000;      // depth steps summed before any verdict
  int max_frames = 30;                  // frames looked at; undecided after them stays so
  // Throws Error unless depth_step > 0, the contrasts finite with unregistered <= registered,
  // min_steps >= 1 and max_frames >= 1.
  void validate() const;
};

// Gradient sums over the depth steps of the frames added so far.
class ColourEdgeProfile {
 public:
  static constexpr int kReach = 8;

  // The frame's depth steps (depth in any units, 0 = none; colour on the depth's pixel grid).
  // Throws Error where the sizes differ.
  void add(const DepthImage& depth, const RgbImage& colour, double depth_step);
  std::uint64_t steps() const { return steps_; }
  // At offset 0 over the mean at |offset| >= 4; 0 before any step.
  double contrast() const;

 private:
  std::array<double, 2 * kReach + 1> sums_{};
  std::uint64_t steps_ = 0;
};

// The verdict over the first frames with colour (ColourRegistrationParams): frames are added until
// a verdict or max_frames, then the verdict is kept.
class ColourRegistrationCheck {
 public:
  explicit ColourRegistrationCheck(ColourRegistrationParams params = {});
  void add(const DepthImage& depth, const RgbImage& colour);
  ColourRegistration verdict() const { return verdict_; }
  double contrast() const { return profile_.contrast(); }
  bool done() const {
    return verdict_ != ColourRegistration::undecided || frames_ >= params_.max_frames;
  }

 private:
  ColourRegistrationParams params_;
  ColourEdgeProfile profile_;
  ColourRegistration verdict_ = ColourRegistration::undecided;
  int frames_ = 0;
};

}  // namespace kartograf::registration
