#pragma once
// Merging neighbouring segments into planes (methods.md M1 step 4). Like the paper, merging grows
// over segments with a stack: the largest unmerged segment that may seed a plane starts one, and
// its neighbours join while they pass the tests against the plane merged so far, which is re-fitted
// from the summed moments (moments are additive) as it grows. The tests:
//  - normal angle (the paper's): for segments large enough to have a reliable normal, the angle to
//    the merged plane's normal is below max_normal_angle_deg;
//  - distance (ours; the paper's fit-error test in a form that also rejects parallel but offset
//    planes): the RMS distance of the segment's points to the merged plane, exact from the
//    moments, is below the allowance (a + b z^2) max(cos t, f) at the segment's centroid (depth
//    z, incidence t on the plane: depth noise is along the viewing ray), and its centroid within
//    offset_base + a fraction of that allowance of the plane;
//  - pixel count and fit error (the paper's): only a segment with at least min_seed_pixels points
//    and its own fit error within the allowance starts a plane.
// A second pass joins neighbouring merged planes, best pair first, while the plane fitted to both
// stays within the allowance (and so does each part) and within the angle of both parts: it repairs
// planes that the first pass split because a noisy seed or a far, noisy surface stopped the growth.
// Planes seen at more than max_incidence_deg from face-on (the surfaces of flying pixels along
// depth edges contain the camera centre) never seed. Neighbours are segments with 8-adjacent pixels
// (default) or, as in the paper, overlapping bounding rectangles. Deterministic: the order is fixed
// by size, then label.
#include <cstdint>
#include <vector>

#include "kartograf/segmentation/plane_fit.hpp"
#include "kartograf/segmentation/region_growing.hpp"

namespace kartograf::segmentation {

enum class NeighbourTest : std::uint8_t {
  pixel_adjacency,       // some pixel of one is among the 8 neighbours of a pixel of the other
  bounding_box_overlap,  // the paper's: bounding rectangles overlap (or touch)
};

struct PlaneMergeParams {
  NeighbourTest neighbours = NeighbourTest::pixel_adjacency;
  double max_normal_angle_deg = 30.0;
  std::uint64_t min_pixels_for_angle = 200;  // smaller segments: distance test only
  std::uint64_t min_seed_pixels = 100;
  // Distance allowance [m] at depth z [m]: distance_base + distance_per_z2 * z^2 (Kinect-like noise
  // grows with z^2).
  double distance_base = 0.01;
  double distance_per_z2 = 0.004;
  // Depth noise is along the viewing ray: on a plane seen at incidence t its distance component
  // shrinks by cos t, and so does the allowance (never below this factor).
  double min_facing_factor = 0.5;
  // Offset: the centroid of a joining segment lies within this fraction of the allowance of the
  // plane (its mean is far more precise than its points: keeps a shelf back or a door leaf a
  // centimetre in front of a wall apart from the wall).
  double max_offset_fraction = 0.2;
  // [m] added to that between touching segments: real sensors bend planes by a few mm.
  double offset_base = 0.005;
  double max_incidence_deg = 80.0;  // angle between the normal and the ray to the centroid
  bool join_planes = true;          // the second pass
  // Also join planes that do not touch (a wall cut in two by a doorway or an occluder) when their
  // normals are within max_apart_angle_deg.
  bool join_apart = true;
  double max_apart_angle_deg = 10.0;
  PlaneFitParams fit;

  void validate() const;  // throws Error naming the first bad field
};

// The distance allowance at `point` (camera frame) for a plane with unit `normal`.
double distance_allowance(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                          const Eigen::Vector3d& normal);

// Segment adjacency as compressed rows: the neighbours of segment s are
// neighbours[offsets[s] .. offsets[s + 1]), ascending.
struct SegmentGraph {
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> neighbours;
};

SegmentGraph pixel_adjacency_graph(const SegmentLabelImage& labels, std::uint32_t segment_count);
SegmentGraph bounding_box_graph(const SegmentLabelImage& labels, std::uint32_t segment_count);

struct MergedPlanes {
  std::vector<std::uint32_t> segment_plane;       // per segment: merged plane index or kNoLabel
  std::vector<geometry::SegmentMoments> moments;  // per merged plane: summed moments
  std::vector<SegmentPlane> planes;               // per merged plane: the re-fit
  SegmentGraph graph;                             // the segments' neighbours
};

// moments.segments and the label image cover the same segment_count segments.
MergedPlanes merge_segments(const SegmentLabelImage& labels,
                            const geometry::SegmentMomentSet& moments,
                            const PlaneMergeParams& params);

}  // namespace kartograf::segmentation
