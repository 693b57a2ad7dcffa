#pragma once
// The files of a map pipeline run (pipeline/map_pipeline.hpp), all in one folder and one map
// frame (z up, floor at z = 0):
//   trajectory.txt          camera-to-map poses (TUM)
//   map.ply                 the map's points: the mesh's vertices with colours and normals
//   mesh.ply                The TSDF's surface, coloured (pipeline/mapper.hpp)
//   band_occupancy.yaml/.pgm  the TSDF's height band as a ROS occupancy grid
//   (mapping/tsdf_slice.hpp) esdf.png                its distance field as grey levels
//   (esdf_picture), same cells planes.json             the map's planes with their classes
//   occupancy.yaml/.pgm     ROS map_server occupancy grid; occupancy.png the same for browsers
//   rooms.png, rooms.json   the rooms in colour over the grid, and their records (rooms_labels.png:
//                           16-bit room ids)
//   semantic.png/.json      the metric-semantic grid with its legend, and its objects
//   top_view.png            the map from above with the trajectory (and the true one if known)
//   report.json             run, per-stage timings, counts and every metric the ground truth allows
//   report.html             the same for people: summary, pictures, plots, a 3-D view
//                           (self-contained: src/io/map_report_html.hpp)
// Each file is written atomically (a reader never sees part of one); everything is rendered
// before the first is written.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/core/image.hpp"
#include "kartograf/outputs/prior_clock.hpp"
#include "kartograf/pipeline/map_evaluation.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"

namespace kartograf::io {

struct MapRunInfo {
  std::string sequence;  // where the frames came from
  std::string layout;    // tum, 7scenes, synthetic, ...
  std::string backend, device;
  bool has_timestamps = true;   // false: trajectory.txt stamps frame numbers
  std::string parameters_json;  // a JSON object (text) stored as "parameters", or empty
  // The input as read, a JSON object (text) stored as "input": the camera, where it came from
  // (preset, file, option, default), the depth scale and the frames left out; or empty.
  std::string input_json;
  std::optional<PriorClock> prior_clock;  // a motion prior file's clock, measured
};

// A distance field (metres) as grey levels: 0 at obstacles and inside them, 255 at 2 m or more.
GrayImage esdf_picture(const Image<float>& esdf);

// The names written by write_map_outputs, in order.
const std::vector<std::string>& map_output_files();

// Writes the files into dir (created if missing), as they are: `kartograf map` gives it a staging
// folder and moves that in as a whole (apps/kartograf/output_transaction.hpp), so that a failed
// or interrupted run never leaves a mix of two runs' files.
void write_map_outputs(const std::filesystem::path& dir, const pipeline::MapPipelineResult& result,
                       const std::optional<pipeline::MapEvaluation>& evaluation,
                       const MapRunInfo& info);

}  // namespace kartograf::io
