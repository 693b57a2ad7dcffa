#pragma once
// The documents of `kartograf planes`: the run's parameters (stored in every planes.json) and a
// sequence's summary.json (the input as read, the run, one record per frame).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kartograf/formats/sequence_detect.hpp"

namespace kartograf::io {

// The extraction's parameters as given to the command, and where it ran.
struct PlaneRunRecord {
  std::string mode;  // regions | cells
  double lab_threshold = 0;
  double normal_angle_deg = 0;
  std::uint64_t min_plane_pixels = 0;
  std::string neighbours;  // pixel | bbox
  std::string fit;         // tls | eq6
  std::string backend, device;
};
// A JSON object on one line, for planes.json's "run" (PlaneFileInfo::run_json).
std::string plane_run_json(const PlaneRunRecord& run);

// One frame's extraction, as summary.json lists it.
struct PlaneFrameRecord {
  std::string source;  // the input's name
  std::string dir;     // where its files are
  std::size_t planes = 0;
  std::uint32_t segments = 0;
  std::size_t valid_pixels = 0, plane_pixels = 0;
  double milliseconds = 0;
};

// summary.json of a sequence folder; ends with a newline.
std::string plane_sequence_summary_json(const std::string& sequence, const OpenedSequence& opened,
                                        const PlaneRunRecord& run,
                                        const std::vector<PlaneFrameRecord>& frames);

}  // namespace kartograf::io
