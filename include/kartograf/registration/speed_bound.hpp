#pragma once
// A robot's speed changes by at most what its drive allows from one frame to the next. Where a
// view's geometry leaves the direction of travel free (a corridor, a floor with a wall out of
// range ahead), features and images may still disagree about the step by a whole tile of a
// repeated floor pattern, and the image residual can prefer the wrong tile (a shorter step warps
// the floor less). A step whose speed lies farther from the last speed the geometry measured than
// the drive could have changed it since is not one the robot made.
//
// SpeedBound learns, from the steps it is given (the odometry gives those of frames whose geometry
// measured every direction and, by default, those the images measured), the largest change of
// step length between two consecutive such frames (metres per frame per frame), and
// admits a step whose length lies within `margin` times that change, per frame since the last
// measured step, of that step's length. It admits every step until it has seen one change larger
// than `least_change_m`: the bound must come from the drive speeding up or slowing down, not from
// a robot at rest or cruising, and a bound under the distance at which two registrations count as
// the same (OdometryParams::feature_arbitration_m) decides nothing. Frames 30 Hz apart never
// change speed that much, so only sparse sequences are bounded. A hand-held camera's speed changes
// erratically, so its bound is wide.
#include <cstddef>
#include <utility>

namespace kartograf::registration {

class SpeedBound {
 public:
  SpeedBound(double margin, double least_change_m)
      : margin_(margin), least_change_m_(least_change_m) {}

  // The step length (metres) into `frame` of a frame whose geometry measured every direction.
  void learn(std::size_t frame, double step_m);

  // Whether a change larger than least_change_m was learned (and margin > 0).
  bool ready() const;

  // Whether a step of `step_m` metres into `frame` (after every learned frame) is within the
  // bound; always true before ready().
  bool admits(std::size_t frame, double step_m) const;

  // The step lengths admits() admits into `frame` (metres; only meaningful once ready()).
  std::pair<double, double> admitted(std::size_t frame) const;

  double largest_change_m() const { return largest_change_m_; }

 private:
  double margin_;
  double least_change_m_;
  bool has_last_ = false;
  std::size_t last_frame_ = 0;
  double last_step_m_ = 0;
  double largest_change_m_ = 0;
};

}  // namespace kartograf::registration
