#include "kartograf/outputs/plane_run.hpp"

#include <utility>

#include "run_json.hpp"

namespace kartograf::io {

namespace {

using detail::RunJson;

RunJson run_json(const PlaneRunRecord& run) {
  return {{"mode", run.mode},
          {"lab_threshold", run.lab_threshold},
          {"normal_angle_deg", run.normal_angle_deg},
          {"min_plane_pixels", run.min_plane_pixels},
          {"neighbours", run.neighbours},
          {"fit", run.fit},
          {"backend", run.backend},
          {"device", run.device}};
}

RunJson frame_json(const PlaneFrameRecord& frame) {
  return {{"source", frame.source},
          {"dir", frame.dir},
          {"planes", frame.planes},
          {"segments", frame.segments},
          {"valid_pixels", frame.valid_pixels},
          {"plane_pixels", frame.plane_pixels},
          {"milliseconds", frame.milliseconds}};
}

}  // namespace

std::string plane_run_json(const PlaneRunRecord& run) {
  return run_json(run).dump();
}

std::string plane_sequence_summary_json(const std::string& sequence, const OpenedSequence& opened,
                                        const PlaneRunRecord& run,
                                        const std::vector<PlaneFrameRecord>& frames) {
  RunJson frame_list = RunJson::array();
  for (const PlaneFrameRecord& frame : frames) frame_list.push_back(frame_json(frame));
  RunJson summary;
  summary["sequence"] = sequence;
  summary["layout"] = to_string(opened.detected.layout);
  summary["input"] = detail::input_json(opened);
  summary["run"] = run_json(run);
  summary["frames"] = std::move(frame_list);
  return summary.dump(1) + "\n";
}

}  // namespace kartograf::io
