#include "kartograf/pipeline/tracking_choices.hpp"

#include "kartograf/core/error.hpp"

namespace kartograf::pipeline {

registration::OdometryParams odometry_params(const TrackingChoices& choices) {
  registration::OdometryParams params;
  params.method = registration::parse_odometry_method(choices.method, "method");
  params.icp = registration::odometry_icp_params(params.method);
  params.reestimate_interval = choices.reestimate_interval;
  params.anchor = {choices.anchor_bounds[0], choices.anchor_bounds[1],
                   static_cast<int>(choices.anchor_bounds[2])};
  return params;
}

mapping::ModelTrackingParams model_tracking_params(const TrackingChoices& choices) {
  require(choices.tracking == "frame" || choices.tracking == "model",
          "tracking: '" + choices.tracking + "' is neither 'frame' nor 'model'");
  mapping::ModelTrackingParams params;
  params.enabled = choices.tracking == "model";
  params.volume.voxel_size = choices.model_voxel;
  params.volume.truncation = 4 * choices.model_voxel;
  return params;
}

}  // namespace kartograf::pipeline
