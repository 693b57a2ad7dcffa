#pragma once
// Frames at a time: how many frames a second a method gets through when `streams` threads each
// extract planes from their own frames with their own instance (one extractor per camera stream,
// as a robot with several cameras or a batch over a recorded sequence runs it), beside the same
// runner with one stream. The main table times one frame at a time, where a frame's serial stages
// (merging, joins, leftovers) keep a second thread idle; this measures throughput, not latency.
#include <iosfwd>
#include <vector>

#include "peer_timing.hpp"
#include "plane_data.hpp"
#include "plane_methods.hpp"

namespace kartograf::peer {

struct ThroughputOptions {
  int streams = 2;        // threads, each with its own instance (0: skip the section)
  double min_time = 0.5;  // seconds each stream keeps going, whole rounds over its frames
};

// For every method with PlaneMethod::another and every data set among the frames: frames per
// second with one stream and with options.streams streams, as a Markdown table.
void print_plane_throughput(std::ostream& out, const std::vector<PlaneMethod>& methods,
                            const std::vector<PlaneFrame>& frames,
                            const ThroughputOptions& options);

}  // namespace kartograf::peer
