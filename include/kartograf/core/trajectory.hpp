#pragma once
// Camera trajectories: timestamped rigid poses (camera-to-world), and the pose at a time between
// two of them.
#include <optional>
#include <vector>

#include <Eigen/Geometry>

namespace kartograf {

struct StampedPose {
  double timestamp = 0;  // seconds
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

using Trajectory = std::vector<StampedPose>;

// How far a time may be from a trajectory's poses for pose_at to answer.
struct PoseAtTolerance {
  double max_gap = 0.5;  // seconds between the two poses an answer interpolates between
  // Seconds to the nearest pose, where no two close enough lie on both sides.
  double max_offset = 0.02;
};

// Sorts by timestamp, keeping the file order of equal ones (pose_at and the clock offset need it).
void sort_by_time(Trajectory& trajectory);

// The pose at time `t` from a trajectory sorted by time: between two poses at most `max_gap` apart,
// interpolated (translation linearly, rotation along the shorter arc), as a sensor sampled at
// another rate than the camera needs; else the nearest pose within `max_offset` (a time just
// outside the trajectory's ends); else none.
std::optional<Eigen::Isometry3d> pose_at(const Trajectory& by_time, double t,
                                         const PoseAtTolerance& tolerance = {});

}  // namespace kartograf
