#pragma once
// The neighbourhood of segments that plane merging walks (docs/methods.md M1 step 4): which
// segments touch (some pixel of one among the 8 neighbours of a pixel of the other), or, as the M1
// paper tests it, whose bounding rectangles overlap.
#include <cstdint>
#include <span>
#include <vector>

#include "kartograf/core/image.hpp"

namespace kartograf::segmentation {

// Segment id per pixel (geometry::kNoLabel: none); see region_growing.hpp.
using SegmentLabelImage = Image<std::uint32_t>;

// Segment adjacency as compressed rows: the neighbours of segment s are
// neighbours[offsets[s] .. offsets[s + 1]), ascending.
struct SegmentGraph {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> neighbours;
};

// Both throw Error for a label >= segment_count (other than kNoLabel).
SegmentGraph pixel_adjacency_graph(const SegmentLabelImage& labels, std::uint32_t segment_count);
SegmentGraph bounding_box_graph(const SegmentLabelImage& labels, std::uint32_t segment_count);

// The graph of undirected edges a != b given as min(a, b) << 32 | max(a, b), repeats allowed.
SegmentGraph graph_from_edges(std::span<const std::uint64_t> edges, std::uint32_t segment_count);

inline std::uint64_t segment_edge(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
}

}  // namespace kartograf::segmentation
