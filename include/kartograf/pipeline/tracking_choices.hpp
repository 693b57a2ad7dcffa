#pragma once
// How a sequence is tracked, by the names a person gives (the CLI's --method, --tracking, ...;
// the Python package's keyword arguments), and the parameters they stand for: one translation for
// every front end, so that the same choices give the same run.
#include <array>
#include <string>

#include "kartograf/mapping/model_tracking.hpp"
#include "kartograf/registration/odometry.hpp"

namespace kartograf::pipeline {

struct TrackingChoices {
  std::string method = "p2plane";  // p2p | p2plane | color | planar
  int reestimate_interval = 5;     // the M3 paper's drift reduction; 0: off
  // The re-estimates' anchor bounds: metres, degrees, frames (registration::AnchorPolicy).
  std::array<double, 3> anchor_bounds{0.4, 25, 100};
  std::string tracking = "frame";  // frame | model (mapping/model_tracking.hpp)
  double model_voxel = 0.02;       // metres: the model's voxels with tracking "model"
};

// Throws Error naming the method or tracking when it is not one of the names above.
registration::OdometryParams odometry_params(const TrackingChoices& choices);
mapping::ModelTrackingParams model_tracking_params(const TrackingChoices& choices);

}  // namespace kartograf::pipeline
