#include "kartograf/segmentation/plane_merge.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

namespace kartograf::segmentation {

namespace {

using geometry::kNoLabel;

// Builds the symmetric compressed graph from undirected edges a < b packed as a << 32 | b.
SegmentGraph graph_from_edges(std::vector<std::uint64_t>& edges, std::uint32_t segment_count) {
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  SegmentGraph graph;
  graph.offsets.assign(std::size_t{segment_count} + 1, 0);
  for (const std::uint64_t e : edges) {
    ++graph.offsets[(e >> 32) + 1];
    ++graph.offsets[(e & 0xffffffffu) + 1];
  }
  std::partial_sum(graph.offsets.begin(), graph.offsets.end(), graph.offsets.begin());
  graph.neighbours.resize(graph.offsets.back());
  std::vector<std::uint32_t> fill(graph.offsets.begin(), graph.offsets.end() - 1);
  // Edges are sorted by (a, b): each row receives its neighbours in ascending order.
  for (const std::uint64_t e : edges) {
    const auto a = static_cast<std::uint32_t>(e >> 32),
               b = static_cast<std::uint32_t>(e & 0xffffffffu);
    graph.neighbours[fill[b]++] = a;
  }
  for (const std::uint64_t e : edges) {
    const auto a = static_cast<std::uint32_t>(e >> 32),
               b = static_cast<std::uint32_t>(e & 0xffffffffu);
    graph.neighbours[fill[a]++] = b;
  }
  return graph;
}

void check_labels(const SegmentLabelImage& labels, std::uint32_t segment_count, const char* what) {
  for (const std::uint32_t l : labels.pixels()) {
    if (l != kNoLabel && l >= segment_count) {  // the message is built only on failure
      throw Error(std::string(what) + ": a pixel has label " + std::to_string(l) +
                  " >= segment count " + std::to_string(segment_count));
    }
  }
}

double allowance(const PlaneMergeParams& params, const Eigen::Vector3d& at,
                 const SegmentPlane& plane) {
  return distance_allowance(params, at, plane.normal);
}

// |cos| of the angle between the plane's normal and the ray to its centroid.
double facing(const SegmentPlane& plane) {
  const double range = plane.centroid.norm();
  return range > 0.0 ? std::fabs(plane.normal.dot(plane.centroid)) / range : 1.0;
}

void add_moments(geometry::SegmentMoments& into, const geometry::SegmentMoments& m) {
  into.count += m.count;
  into.sum += m.sum;
  into.sum_outer += m.sum_outer;
}

// Second pass: joins adjacent merged planes, lowest cost first (cost: RMS of the joint fit over the
// allowance at its depth; joins only below 1 and within the angle). Planes absorbed into another
// are left with count 0 and are compacted by the caller.
void join_adjacent_planes(const SegmentGraph& graph, const PlaneMergeParams& params,
                          const Eigen::Vector3d& origin, double min_cos, MergedPlanes& merged) {
  const std::size_t plane_count = merged.planes.size();
  // Planes touch when segments of theirs are adjacent; they are near when both touch one unmerged
  // segment (a gap left by the first pass must not keep two pieces of one plane apart).
  enum Relation : std::uint8_t { apart = 0, near = 1, touching = 2 };
  std::vector<std::vector<std::uint32_t>> adjacent(plane_count), near_planes(plane_count);
  std::vector<std::uint32_t> around;
  for (std::uint32_t s = 0; s + 1 < graph.offsets.size(); ++s) {
    const std::uint32_t p = merged.segment_plane[s];
    around.clear();
    for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1]; ++k) {
      const std::uint32_t q = merged.segment_plane[graph.neighbours[k]];
      if (q != kNoLabel && q != p) around.push_back(q);
    }
    if (p != kNoLabel) {
      adjacent[p].insert(adjacent[p].end(), around.begin(), around.end());
      continue;
    }
    for (const std::uint32_t a : around) {
      for (const std::uint32_t b : around) {
        if (a != b) near_planes[a].push_back(b);
      }
    }
  }
  const double min_cos_apart = std::cos(params.max_apart_angle_deg * M_PI / 180.0);
  // Cost of joining p and q (>= 1: no). Each side must lie within the allowance at its own depth
  // of the joint plane, so a far noisy surface cannot drag a near one along. Pairs that are not
  // near (a plane cut in two by an occluder or a doorway) must also be nearly parallel.
  const auto cost = [&](std::uint32_t p, std::uint32_t q, Relation relation) {
    const bool adjacent_pair = relation != apart;
    const SegmentPlane& a = merged.planes[p];
    const SegmentPlane& b = merged.planes[q];
    if (!a.valid || !b.valid) return 2.0;
    const double cos_ab = std::fabs(a.normal.dot(b.normal));
    if (cos_ab < (adjacent_pair ? min_cos : min_cos_apart)) return 2.0;
    const double limit_a = allowance(params, a.centroid, b),
                 limit_b = allowance(params, b.centroid, a);
    // Cheap necessary test first: each side near the other's plane.
    if (!adjacent_pair && (mean_squared_distance(merged.moments[q], origin, a.normal, a.offset) >
                               4.0 * limit_b * limit_b ||
                           mean_squared_distance(merged.moments[p], origin, b.normal, b.offset) >
                               4.0 * limit_a * limit_a)) {
      return 2.0;
    }
    geometry::SegmentMoments both = merged.moments[p];
    add_moments(both, merged.moments[q]);
    const SegmentPlane joint = fit_plane(both, origin, params.fit);
    // Two parallel pieces with a step between them fit a plane tilted to both: the joint plane
    // itself must keep within the angle of each.
    if (!joint.valid || std::fabs(joint.normal.dot(a.normal)) < min_cos ||
        std::fabs(joint.normal.dot(b.normal)) < min_cos) {
      return 2.0;
    }
    const auto side = [&](std::uint32_t r, const SegmentPlane& own) {
      const double limit = allowance(params, own.centroid, joint);
      const double rms =
          std::sqrt(mean_squared_distance(merged.moments[r], origin, joint.normal, joint.offset));
      const double shift = std::fabs(joint.normal.dot(own.centroid) + joint.offset);
      // The base term is for sensor bending within one continuous surface, not across a gap.
      const double base = relation == touching ? params.offset_base : 0.0;
      return std::max(rms / limit, shift / (base + params.max_offset_fraction * limit));
    };
    return std::max(
        {joint.rms_error / allowance(params, joint.centroid, joint), side(p, a), side(q, b)});
  };
  // Cached costs of every pair (upper triangle); a join recomputes the row of the joined plane.
  std::vector<std::uint8_t> is_adjacent(plane_count * plane_count, 0);
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (const std::uint32_t q : near_planes[p])
      is_adjacent[p * plane_count + q] = is_adjacent[q * plane_count + p] = near;
  }
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (const std::uint32_t q : adjacent[p])
      is_adjacent[p * plane_count + q] = is_adjacent[q * plane_count + p] = touching;
  }
  std::vector<double> pair_cost(plane_count * plane_count, 2.0);
  const auto evaluate = [&](std::uint32_t p, std::uint32_t q) {
    const std::uint32_t lo = std::min(p, q), hi = std::max(p, q);
    const auto relation = static_cast<Relation>(is_adjacent[lo * plane_count + hi]);
    pair_cost[lo * plane_count + hi] =
        relation != apart || params.join_apart ? cost(lo, hi, relation) : 2.0;
  };
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (std::uint32_t q = p + 1; q < plane_count; ++q) evaluate(p, q);
  }
  std::vector<std::uint32_t> alias(plane_count);
  std::iota(alias.begin(), alias.end(), 0u);
  for (;;) {
    double best = 1.0;
    std::uint32_t best_p = kNoLabel, best_q = kNoLabel;
    for (std::uint32_t p = 0; p < plane_count; ++p) {
      for (std::uint32_t q = p + 1; q < plane_count; ++q) {
        if (pair_cost[p * plane_count + q] < best)
          best = pair_cost[p * plane_count + q], best_p = p, best_q = q;
      }
    }
    if (best_p == kNoLabel) break;
    // q joins p: moments, fit, adjacency and the costs involving either.
    add_moments(merged.moments[best_p], merged.moments[best_q]);
    merged.moments[best_q] = {};
    merged.planes[best_p] = fit_plane(merged.moments[best_p], origin, params.fit);
    merged.planes[best_q] = {};
    alias[best_q] = best_p;
    for (std::uint32_t r = 0; r < plane_count; ++r) {
      const std::uint8_t relation =
          std::max(is_adjacent[best_p * plane_count + r], is_adjacent[best_q * plane_count + r]);
      is_adjacent[best_p * plane_count + r] = is_adjacent[r * plane_count + best_p] = relation;
      const std::uint32_t lo = std::min(r, best_q), hi = std::max(r, best_q);
      pair_cost[lo * plane_count + hi] = 2.0;
    }
    is_adjacent[best_p * plane_count + best_p] = 0;
    for (std::uint32_t r = 0; r < plane_count; ++r) {
      if (r != best_p && merged.moments[r].count > 0) evaluate(best_p, r);
    }
  }
  // Compact: drop absorbed planes, renumber in order.
  std::vector<std::uint32_t> renumber(plane_count, kNoLabel);
  MergedPlanes compact;
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    if (merged.moments[p].count == 0) continue;
    renumber[p] = static_cast<std::uint32_t>(compact.planes.size());
    compact.planes.push_back(merged.planes[p]);
    compact.moments.push_back(merged.moments[p]);
  }
  compact.segment_plane = std::move(merged.segment_plane);
  compact.graph = std::move(merged.graph);
  for (std::uint32_t& p : compact.segment_plane) {
    if (p == kNoLabel) continue;
    while (alias[p] != p) p = alias[p];
    p = renumber[p];
  }
  merged = std::move(compact);
}

}  // namespace

double distance_allowance(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                          const Eigen::Vector3d& normal) {
  const double range = point.norm();
  const double facing = range > 0.0 ? std::fabs(normal.dot(point)) / range : 1.0;
  return (params.distance_base + params.distance_per_z2 * point.z() * point.z()) *
         std::max(facing, params.min_facing_factor);
}

void PlaneMergeParams::validate() const {
  require(std::isfinite(max_normal_angle_deg) && max_normal_angle_deg >= 0 &&
              max_normal_angle_deg <= 180,
          "plane merge: max_normal_angle_deg must be in [0, 180], got " +
              std::to_string(max_normal_angle_deg));
  require(std::isfinite(distance_base) && distance_base >= 0,
          "plane merge: distance_base must be >= 0, got " + std::to_string(distance_base));
  require(std::isfinite(distance_per_z2) && distance_per_z2 >= 0,
          "plane merge: distance_per_z2 must be >= 0, got " + std::to_string(distance_per_z2));
  require(distance_base + distance_per_z2 > 0, "plane merge: the distance allowance is zero");
  require(std::isfinite(max_offset_fraction) && max_offset_fraction > 0,
          "plane merge: max_offset_fraction must be positive, got " +
              std::to_string(max_offset_fraction));
  require(std::isfinite(offset_base) && offset_base >= 0,
          "plane merge: offset_base must be >= 0, got " + std::to_string(offset_base));
  require(
      std::isfinite(min_facing_factor) && min_facing_factor > 0 && min_facing_factor <= 1,
      "plane merge: min_facing_factor must be in (0, 1], got " + std::to_string(min_facing_factor));
  require(std::isfinite(max_incidence_deg) && max_incidence_deg > 0 && max_incidence_deg <= 90,
          "plane merge: max_incidence_deg must be in (0, 90], got " +
              std::to_string(max_incidence_deg));
}

SegmentGraph pixel_adjacency_graph(const SegmentLabelImage& labels, std::uint32_t segment_count) {
  check_labels(labels, segment_count, "pixel adjacency graph");
  const int width = labels.width(), height = labels.height();
  std::vector<std::uint64_t> edges;
  std::uint64_t last = ~std::uint64_t{0};
  const auto add = [&](std::uint32_t a, std::uint32_t b) {
    if (a == b || b == kNoLabel) return;
    const std::uint64_t key = a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
    if (key != last) edges.push_back(key);  // runs along a boundary repeat the same pair
    last = key;
  };
  // Each unordered 8-neighbour pair once: right, down-left, down, down-right.
  for (int y = 0; y < height; ++y) {
    const std::uint32_t* row = &labels(0, y);
    const std::uint32_t* below = y + 1 < height ? &labels(0, y + 1) : nullptr;
    for (int x = 0; x < width; ++x) {
      const std::uint32_t a = row[x];
      if (a == kNoLabel) continue;
      if (x + 1 < width) add(a, row[x + 1]);
      if (below == nullptr) continue;
      if (x > 0) add(a, below[x - 1]);
      add(a, below[x]);
      if (x + 1 < width) add(a, below[x + 1]);
    }
  }
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
      edges.push_back(std::uint64_t{p} << 32 | q);
    }
  }
  return graph_from_edges(edges, segment_count);
}

MergedPlanes merge_segments(const SegmentLabelImage& labels,
                            const geometry::SegmentMomentSet& moments,
                            const PlaneMergeParams& params) {
  params.validate();
  const auto segment_count = static_cast<std::uint32_t>(moments.segments.size());
  const SegmentGraph graph = params.neighbours == NeighbourTest::pixel_adjacency
                                 ? pixel_adjacency_graph(labels, segment_count)
                                 : bounding_box_graph(labels, segment_count);
  const std::vector<geometry::SegmentMoments>& segments = moments.segments;
  const Eigen::Vector3d& origin = moments.origin;
  const double min_cos = std::cos(params.max_normal_angle_deg * M_PI / 180.0);
  const double min_facing = std::cos(params.max_incidence_deg * M_PI / 180.0);
  const auto centroid_of = [&](const geometry::SegmentMoments& m) -> Eigen::Vector3d {
    return origin + m.sum / static_cast<double>(m.count);
  };
  // Fits only where a test needs them (most segments of a textured frame are tiny).
  const std::uint64_t min_fit_pixels =
      std::min(params.min_pixels_for_angle, params.min_seed_pixels);
  std::vector<SegmentPlane> fits(segment_count);
  for (std::uint32_t s = 0; s < segment_count; ++s) {
    if (segments[s].count >= min_fit_pixels) fits[s] = fit_plane(segments[s], origin, params.fit);
  }

  std::vector<std::uint32_t> order;
  for (std::uint32_t s = 0; s < segment_count; ++s) {
    if (segments[s].count >= params.min_seed_pixels) order.push_back(s);
  }
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return segments[a].count != segments[b].count ? segments[a].count > segments[b].count : a < b;
  });

  MergedPlanes result;
  result.segment_plane.assign(segment_count, kNoLabel);
  std::vector<std::uint32_t> stack;
  for (const std::uint32_t seed : order) {
    const SegmentPlane& seed_fit = fits[seed];
    if (result.segment_plane[seed] != kNoLabel || !seed_fit.valid) continue;
    if (seed_fit.rms_error > allowance(params, seed_fit.centroid, seed_fit))
      continue;  // not planar
    if (facing(seed_fit) < min_facing) continue;
    const auto plane_index = static_cast<std::uint32_t>(result.planes.size());
    geometry::SegmentMoments merged = segments[seed];
    SegmentPlane plane = seed_fit;
    std::uint64_t fitted_count = merged.count;
    result.segment_plane[seed] = plane_index;
    stack.assign(graph.neighbours.begin() + graph.offsets[seed],
                 graph.neighbours.begin() + graph.offsets[seed + 1]);
    while (!stack.empty()) {
      const std::uint32_t s = stack.back();
      stack.pop_back();
      if (result.segment_plane[s] != kNoLabel || segments[s].count == 0) continue;
      const geometry::SegmentMoments& m = segments[s];
      if (m.count >= params.min_pixels_for_angle) {
        if (!fits[s].valid || std::fabs(fits[s].normal.dot(plane.normal)) < min_cos) continue;
      }
      const double limit = allowance(params, centroid_of(m), plane);
      if (mean_squared_distance(m, origin, plane.normal, plane.offset) > limit * limit) continue;
      const double shift = plane.normal.dot(centroid_of(m)) + plane.offset;
      if (std::fabs(shift) > params.offset_base + params.max_offset_fraction * limit)
        continue;  // parallel, offset
      result.segment_plane[s] = plane_index;
      add_moments(merged, m);
      // Re-fit as the plane grows by a quarter: deterministic, and few eigen solves.
      if (merged.count * 4 >= fitted_count * 5) {
        const SegmentPlane refit = fit_plane(merged, origin, params.fit);
        if (refit.valid) plane = refit;
        fitted_count = merged.count;
      }
      for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1]; ++k) {
        if (result.segment_plane[graph.neighbours[k]] == kNoLabel)
          stack.push_back(graph.neighbours[k]);
      }
    }
    const SegmentPlane final_fit = fit_plane(merged, origin, params.fit);
    result.moments.push_back(merged);
    result.planes.push_back(final_fit.valid ? final_fit : plane);
  }
  result.graph = graph;
  if (params.join_planes) join_adjacent_planes(graph, params, origin, min_cos, result);
  return result;
}

}  // namespace kartograf::segmentation
