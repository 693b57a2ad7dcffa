#pragma once
// Camera trajectories through the synthetic world (camera-to-world poses, TUM optical frame).
//
// robot_tour: a camera on a robot driving the world's route (synth/route.hpp): through every
// room and back to the start, looking left and right in each room. The speed along the route is
// set so that no frame moves more than max_step or turns more than max_yaw_step_deg, and it
// changes continuously (C1 positions). When the frame count is too small for the full
// look-around, the look-around shrinks; below tour_frames_needed frames even the bare route
// exceeds the limits (the tour then moves faster).
//
// handheld: a smooth hand-held motion inside one room: slow drifts in position, a sweep in yaw,
// small pitch and roll wobble.
#include <cstdint>

#include <Eigen/Geometry>

#include "kartograf/core/trajectory.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::synth {

struct TourParams {
  double camera_height = 1.0;     // metres above the floor
  double pitch_deg = 12.0;        // downwards
  double look_around_deg = 30.0;  // yaw sweep inside each room: up to this far left, then right
  // Survey: instead of looking left and right, stop once in each room and on each pass through
  // the corridor, at the route's point farthest from walls and furniture there, and turn all the
  // way round in place, as a robot exploring the building would (sees every room's floor and
  // walls; needs about 100 frames more per turn at max_yaw_step_deg 4).
  bool survey = false;
  double max_step = 0.12;         // metres per frame
  double max_yaw_step_deg = 4.0;  // degrees per frame
  double frame_rate = 30.0;       // Hz: timestamps are start_time + i / frame_rate
  double start_time = 0.0;

  void validate() const;
};

// frame_count >= 2 frames; the last pose equals the first (the route is a loop).
Trajectory robot_tour(const World& world, int frame_count, const TourParams& options = {});

// The least number of frames for which the tour, without looking around, stays within max_step
// and max_yaw_step_deg.
int tour_frames_needed(const World& world, const TourParams& options = {});

struct HandheldParams {
  double height = 1.45;  // metres: mean camera height
  double frame_rate = 30.0;
  double start_time = 0.0;
};

// A hand-held sequence in `room` (a World::rooms id), centred on the room's point farthest from
// walls and furniture. Deterministic in seed.
Trajectory handheld(const World& world, Label room, int frame_count, std::uint64_t seed,
                    const HandheldParams& options = {});

// Camera-to-world pose (TUM optical frame) of a camera at `position` whose viewing direction has
// heading yaw (from +x towards +y) and is pitched down by pitch; roll turns it about the view.
Eigen::Isometry3d camera_pose(const Eigen::Vector3d& position, double yaw, double pitch_down,
                              double roll = 0.0);

// The point of `room` farthest from its walls and from furniture and door leaves (searched on a
// 5 cm grid), and that distance.
std::pair<Eigen::Vector2d, double> most_open_point(const World& world, Label room);

}  // namespace kartograf::synth
