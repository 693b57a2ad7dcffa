#pragma once
// What report.json records about a map pipeline run (MapRunInfo for write_map_outputs): the
// sequence as given and as read, where it ran, and the pipeline's parameters.
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/outputs/map_outputs.hpp"
#include "kartograf/outputs/odometry_stats.hpp"
#include "kartograf/pipeline/mapper.hpp"

namespace kartograf::io {

MapRunInfo map_run_info(const SequenceRunRecord& record, const OpenedSequence& opened,
                        const pipeline::MapperParams& params);

}  // namespace kartograf::io
