#pragma once
// A picture of the synthetic world's floor plan for people to look at: rooms tinted, walls dark,
// doorways and door leaves brown, furniture grey, the camera trajectory in red (start green,
// viewing direction every second as a short tick) and the laser scanner in blue.
#include <optional>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/trajectory.hpp"
#include "kartograf/synth/floor_plan.hpp"

namespace kartograf::synth {

// `scale` pixels per floor-plan cell; ticks every `tick_every` frames (0: none).
RgbImage floor_plan_preview(const FloorPlan& plan, const Trajectory& trajectory,
                            const std::optional<Eigen::Isometry3d>& scanner = std::nullopt,
                            int scale = 3, int tick_every = 30);

}  // namespace kartograf::synth
