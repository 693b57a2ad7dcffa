#pragma once
// The offset between two clocks, measured from how fast two trajectories of one rigid body turn:
// a camera's poses (from its images) and another sensor's (a robot's wheel odometry, a motion
// capture) stamped by another clock. Each step of the sparser of the two (its rotation angle
// between consecutive poses) is compared with the denser one's rotation over the same span, read
// with the other clock `offset` seconds ahead; the offset where they agree best is its lead.
// Rotation angles are the same in every frame of the body (a mount rotation conjugates them) and do
// not depend on the other sensor's translation scale (wheel slip, a wrong wheel radius), so neither
// spoils the estimate; the camera must turn, and not at one constant rate (then every offset agrees
// equally: not observable).
#include <cstddef>
#include <limits>

#include "kartograf/core/trajectory.hpp"

namespace kartograf::eval {

struct ClockOffsetSearch {
  double given_s = 0;         // the offset in use, whose agreement the estimate reports too
  double half_range_s = 0.5;  // offsets tried: given_s +- half_range_s
  // A step's disagreement counts at most this much (an odometry failure is not evidence), and a
  // step the other trajectory has no poses for at an offset counts this much there.
  double outlier_deg = 1.0;
  double max_sigma_s = 0.01;  // a standard error above this: not observable
};

struct ClockOffsetEstimate {
  double offset_s = 0;  // read the other trajectory at a frame's time + offset_s
  // Standard error of offset_s from the agreement's curvature (infinite when flat).
  double sigma_s = std::numeric_limits<double>::infinity();
  double rms_deg = 0;        // the steps' rotation disagreement at offset_s (deg per step)
  double given_rms_deg = 0;  // and at ClockOffsetSearch::given_s
  std::size_t steps = 0;     // steps compared (of the sparser trajectory, inside the other's span)
  // The best offset lies inside the search range and is known to max_sigma_s.
  bool observable = false;
};

// `frames` and `other` sorted by time (their poses are read with pose_at: interpolated between
// samples at most 0.5 s apart). Throws Error on a search range, outlier or sigma limit that is
// not positive, or a value that is not finite.
ClockOffsetEstimate estimate_clock_offset(const Trajectory& frames, const Trajectory& other,
                                          const ClockOffsetSearch& search = {});

}  // namespace kartograf::eval
