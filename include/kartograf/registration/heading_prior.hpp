#pragma once
// A camera on a wheeled robot moves along the robot's heading: its step, with half the step's
// turn undone, points the same way in the camera frame every frame (forward and, for a camera
// tilted down, a little up), and a turn on the spot moves it not at all. Nothing moves it
// sideways. Where a frame's geometry leaves the sideways slide free (a wall over the floor,
// ahead) the odometry can take that slide from this instead of from ICP's or the images'
// weakest answer.
//
// HeadingPrior learns, from the steps of frames whose geometry measured every direction, the
// direction of travel (a mean weighted by step length) and how far the steps stray across it
// (the mean square of the component across it): a robot's steps stray by the odometry's own
// noise (a few tenths of a millimetre on the synthetic surveys), a hand-held camera's by
// millimetres to centimetres, which makes the prior too weak to matter there. Both means decay
// over about the last 20 such frames.
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/se3.hpp"

namespace kartograf::registration {

// A step's translation with half its turn undone: on an arc of constant curvature, the direction
// of travel at no turn (camera frame of the step's start).
Eigen::Vector3d untwisted(const Eigen::Isometry3d& step);

// The unit direction of travel on `step`'s arc: `heading` (the direction at no turn) turned by
// half the step's turn.
Eigen::Vector3d travel_on_arc(const Eigen::Vector3d& heading, const Eigen::Isometry3d& step);

// A grid of steps along the heading (HeadingPrior::steps_around): lengths (metres) and turns
// (radians) about a step's own.
struct HeadingStepGrid {
  double shortest = 0, longest = 0, length_spacing = 0.02;
  double max_turn = 0, turn_spacing = 0;
  Eigen::Vector3d turn_axis = Eigen::Vector3d::UnitY();  // camera frame, unit
  bool backwards = false;                                // against the heading (a robot reversing)
};

class HeadingPrior {
 public:
  // One step (T_{n-1}^-1 T_n, camera frames) of a frame whose geometry measured every direction.
  void learn(const Eigen::Isometry3d& step);

  // The direction of travel with no turn (camera frame); its length is a decaying weighted
  // mean, only its direction means anything. Zero before the first step.
  const Eigen::Vector3d& heading() const { return heading_; }

  // The unit direction of travel on `step`'s arc (camera frame of the step's start): the heading
  // turned by half the step's turn. Zero before the first step.
  Eigen::Vector3d travel_on(const Eigen::Isometry3d& step) const;

  // The axis the camera turns about (camera frame, unit: a robot's vertical; its sign
  // arbitrary), a mean of the learned steps' axes weighted by their turns, over those turning
  // more than 2 degrees. Zero before the first such step.
  Eigen::Vector3d turn_axis() const;

  // `step`'s turn changed by each of the grid's turns, each with each of its lengths along the
  // direction of travel on that turn's arc: the steps a robot can have made from where `step`
  // turned to. Empty before the first learned step.
  std::vector<Eigen::Isometry3d> steps_around(const Eigen::Isometry3d& step,
                                              const HeadingStepGrid& grid) const;

  // Whether enough steps were learned for the spread to mean anything.
  bool ready() const;

  // The mean square (m^2) of the learned steps' component across the heading.
  double across_variance() const;

  // The information (right perturbation of `step`, (omega, v), 1/m^2) of the prior that the
  // step's translation, with half its turn undone, has no component across the heading.
  se3::Matrix6d information(const Eigen::Isometry3d& step) const;

  // `step` moved as far as `measured` (its information, the same coordinates) lets the prior
  // move it: the Gauss-Newton minimum of both. Directions neither measures stay.
  Eigen::Isometry3d combine(const Eigen::Isometry3d& step, const se3::Matrix6d& measured) const;

 private:
  Eigen::Vector3d heading_ = Eigen::Vector3d::Zero();
  double across_squared_ = 0;  // decaying sums
  double weight_ = 0;
  Eigen::Vector3d turn_axis_ = Eigen::Vector3d::Zero();  // decaying sum of axis times angle
};

}  // namespace kartograf::registration
