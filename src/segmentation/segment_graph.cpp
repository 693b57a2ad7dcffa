#include "kartograf/segmentation/segment_graph.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <string>

#include "compute/cpu_parallel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/geometry/segment_moments.hpp"

namespace kartograf::segmentation {

namespace {

using geometry::kNoLabel;

void check_labels(const SegmentLabelImage& labels, std::uint32_t segment_count, const char* what) {
  // Labels wrap to values >= segment_count when kNoLabel + 1 turns 0: one compare per pixel.
  std::uint32_t worst = 0;
  for (const std::uint32_t l : labels.pixels()) worst = std::max(worst, l + 1);
  if (worst > segment_count) {  // the message is built only on failure
    throw Error(std::string(what) + ": a pixel has label " + std::to_string(worst - 1) +
                " >= segment count " + std::to_string(segment_count));
  }
}

}  // namespace

// Builds the symmetric compressed graph from undirected edges a < b packed as a << 32 | b.
// Bucketed by segment, then each short row sorted and deduplicated (linear time; a sort of all
// edges costs more).
SegmentGraph graph_from_edges(std::span<const std::uint64_t> edges, std::uint32_t segment_count) {
  std::vector<std::uint32_t> starts(std::size_t{segment_count} + 1, 0);
  for (const std::uint64_t e : edges) {
    ++starts[(e >> 32) + 1];
    ++starts[(e & 0xffffffffu) + 1];
  }
  std::partial_sum(starts.begin(), starts.end(), starts.begin());
  std::vector<std::uint32_t> bucket(starts.back());
  std::vector<std::uint32_t> fill(starts.begin(), starts.end() - 1);
  for (const std::uint64_t e : edges) {
    const auto a = static_cast<std::uint32_t>(e >> 32),
               b = static_cast<std::uint32_t>(e & 0xffffffffu);
    bucket[fill[a]++] = b;
    bucket[fill[b]++] = a;
  }
  SegmentGraph graph;
  graph.offsets.assign(std::size_t{segment_count} + 1, 0);
  graph.neighbours.reserve(bucket.size());
  for (std::uint32_t s = 0; s < segment_count; ++s) {
    const auto row = bucket.begin() + starts[s], row_end = bucket.begin() + starts[s + 1];
    std::sort(row, row_end);
    graph.neighbours.insert(graph.neighbours.end(), row, std::unique(row, row_end));
    graph.offsets[s + 1] = static_cast<std::uint32_t>(graph.neighbours.size());
  }
  return graph;
}

SegmentGraph pixel_adjacency_graph(const SegmentLabelImage& labels, std::uint32_t segment_count) {
  const int width = labels.width(), height = labels.height();
  // Rows in chunks on the CPU backend's threads; the edges are sorted and deduplicated after, so
  // the graph does not depend on the thread count.
  std::array<std::vector<std::uint64_t>, compute::detail::kCpuChunks> chunk_edges;
  // The labels are checked as they are read: the largest label + 1 of each chunk (0 for none).
  std::array<std::uint32_t, compute::detail::kCpuChunks> chunk_worst{};
  compute::detail::for_each_chunk(
      static_cast<std::size_t>(height), labels.size(),
      [&](std::size_t first_row, std::size_t end_row, std::size_t chunk) {
        std::vector<std::uint64_t>& edges = chunk_edges[chunk];
        std::uint32_t worst = 0;
        // Runs along a boundary repeat the same pair: each segment remembers its last partner,
        // which drops most repeats before the sort.
        std::vector<std::uint32_t> last_partner(segment_count, kNoLabel);
        const auto add = [&](std::uint32_t a, std::uint32_t b) {
          if (a == b || b == kNoLabel) return;
          if (a > b) std::swap(a, b);
          if (last_partner[a] == b) return;
          last_partner[a] = b;
          edges.push_back(segment_edge(a, b));
        };
        // Each unordered 8-neighbour pair once: right, down-left, down, down-right.
        for (int y = static_cast<int>(first_row); y < static_cast<int>(end_row); ++y) {
          const std::uint32_t* row = &labels(0, y);
          const std::uint32_t* below = y + 1 < height ? &labels(0, y + 1) : nullptr;
          for (int x = 0; x < width; ++x) {
            const std::uint32_t a = row[x];
            worst = std::max(worst, a + 1);  // kNoLabel + 1 wraps to 0
            if (a == kNoLabel || a >= segment_count) continue;
            // Inside a segment all four are equal: one test for the common case.
            if (below != nullptr && x > 0 && x + 1 < width &&
                ((a ^ row[x + 1]) | (a ^ below[x - 1]) | (a ^ below[x]) | (a ^ below[x + 1])) ==
                    0) {
              continue;
            }
            if (x + 1 < width) add(a, row[x + 1]);
            if (below == nullptr) continue;
            if (x > 0) add(a, below[x - 1]);
            add(a, below[x]);
            if (x + 1 < width) add(a, below[x + 1]);
          }
        }
        chunk_worst[chunk] = worst;
      });
  const std::uint32_t worst = *std::max_element(chunk_worst.begin(), chunk_worst.end());
  if (worst > segment_count) {  // the message is built only on failure
    throw Error("pixel adjacency graph: a pixel has label " + std::to_string(worst - 1) +
                " >= segment count " + std::to_string(segment_count));
  }
  std::vector<std::uint64_t> edges = std::move(chunk_edges[0]);
  for (std::size_t c = 1; c < chunk_edges.size(); ++c)
    edges.insert(edges.end(), chunk_edges[c].begin(), chunk_edges[c].end());
  return graph_from_edges(edges, segment_count);
}

SegmentGraph bounding_box_graph(const SegmentLabelImage& labels, std::uint32_t segment_count) {
  check_labels(labels, segment_count, "bounding box graph");
  struct Box {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  };
  std::vector<Box> boxes(segment_count);
  for (int y = 0; y < labels.height(); ++y) {
    for (int x = 0; x < labels.width(); ++x) {
      const std::uint32_t l = labels(x, y);
      if (l == kNoLabel) continue;
      Box& b = boxes[l];
      b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x), b.y0 = std::min(b.y0, y),
      b.y1 = std::max(b.y1, y);
    }
  }
  // Sweep along x: boxes sorted by x0; touching boxes (gap 0) count as overlapping, as 8-adjacent
  // pixels do.
  std::vector<std::uint32_t> order(segment_count);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return boxes[a].x0 != boxes[b].x0 ? boxes[a].x0 < boxes[b].x0 : a < b;
  });
  std::vector<std::uint64_t> edges;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Box& a = boxes[order[i]];
    if (a.x1 < 0) continue;
    for (std::size_t j = i + 1; j < order.size() && boxes[order[j]].x0 <= a.x1 + 1; ++j) {
      const Box& b = boxes[order[j]];
      if (b.x1 < 0 || b.y0 > a.y1 + 1 || a.y0 > b.y1 + 1) continue;
      const std::uint32_t p = std::min(order[i], order[j]), q = std::max(order[i], order[j]);
      edges.push_back(segment_edge(p, q));
    }
  }
  return graph_from_edges(edges, segment_count);
}

}  // namespace kartograf::segmentation
