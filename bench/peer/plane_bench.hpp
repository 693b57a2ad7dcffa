#pragma once
// The plane benchmark: Kartograf's PlaneExtractor in both modes (kartograf_plane_bench), and in
// kartograf_peer_bench (issue 5, part 8) beside PCL's OrganizedMultiPlaneSegmentation and Open3D's
// SegmentPlane loop on the same frames, in one run.
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "peer_timing.hpp"
#include "plane_methods.hpp"
#include "plane_throughput.hpp"

namespace kartograf::peer {

struct PlaneBenchOptions {
  int synthetic_frames = 12;           // robot-tour frames with exact plane ids (0: none)
  std::filesystem::path seven_scenes;  // '' to skip
  std::vector<std::size_t> seven_scenes_frames = {0, 30, 60, 90, 120, 150, 180, 210, 240, 270};
  std::filesystem::path mosd;  // PCL's mOSD folder, '' to skip
  int ransac_max_planes = 20;  // Open3D's loop stops after this many planes
  bool device_backends = true;
  std::string only;                // run only methods whose name contains this
  bool details = false;            // every frame's time and scores on stderr
  std::filesystem::path overlays;  // write each method's planes over each frame here (PNG)
  TimingOptions timing;
  ThroughputOptions throughput;    // the frames-at-a-time table (streams 0: none)
  std::vector<PlaneMethod> peers;  // run after Kartograf's own rows
};

// Prints the section's heading, what was run and its tables (Markdown) to out; progress to stderr.
void run_plane_bench(const PlaneBenchOptions& options, std::ostream& out);

}  // namespace kartograf::peer
