#include "kartograf/outputs/map_run_info.hpp"

#include <string>

#include "run_json.hpp"

namespace kartograf::io {

namespace {

// The parameters a run can change (options of `kartograf map`), a JSON object.
detail::RunJson parameters_json(const std::string& method, const pipeline::MapperParams& mapper) {
  const pipeline::MapPipelineParams& p = mapper.pipeline;
  return {{"method", method},
          {"reestimate_interval", p.slam.odometry.reestimate_interval},
          {"tracking", p.slam.model.enabled ? "model" : "frame"},
          {"features", p.features},
          {"model_voxel_m", p.slam.model.volume.voxel_size},
          {"label_step", p.label_step},
          {"max_views", p.max_views},
          {"label_width", p.label_width},
          {"grid_resolution_m", p.grid.resolution},
          {"tsdf_voxel_m", mapper.volume.voxel_size},
          {"tsdf_truncation_m", mapper.volume.truncation},
          {"tsdf_budget_blocks", mapper.volume.max_blocks},
          {"room_method", rooms::to_string(p.room_method)},
          {"rooms_end_at_doorways", p.rooms_end_at_doorways},
          {"rooms_take_enclosed", p.rooms_take_enclosed},
          {"room_fragment_area_m2", p.room_fragment_area_m2}};
}

}  // namespace

MapRunInfo map_run_info(const SequenceRunRecord& record, const OpenedSequence& opened,
                        const pipeline::MapperParams& params) {
  MapRunInfo info;
  info.sequence = record.sequence;
  info.layout = std::string(to_string(opened.detected.layout));
  info.backend = record.backend;
  info.device = record.device;
  info.has_timestamps = opened.detected.has_timestamps;
  info.parameters_json = parameters_json(record.method, params).dump();
  info.input_json = detail::input_json(opened).dump();
  return info;
}

}  // namespace kartograf::io
