#pragma once
// Merging neighbouring segments into planes (docs/methods.md M1 step 4). Like the paper, merging
// grows over segments with a stack: the largest unmerged segment that may seed a plane starts one,
// and its neighbours join while they pass the tests against the plane merged so far, which is
// re-fitted from the summed moments (moments are additive) as it grows. The tests:
//  - normal angle (the paper's): for segments large enough to have a normal, the angle to the
//    merged plane's normal is below max_normal_angle_deg, widened by the normal's uncertainty
//    (normal_uncertainty_deg: a narrow strip, or a slanted far surface that the sensor's depth
//    quantization turns into bands of constant depth, has a normal that noise can tilt far);
//  - distance (ours; the paper's fit-error test in a form that also rejects parallel but offset
//    planes): the RMS distance of the segment's points to the merged plane, exact from the
//    moments, is below the allowance (a + b z^2) max(cos t, f) at the segment's centroid (depth
//    z, incidence t on the plane: depth noise is along the viewing ray) and below
//    max_joint_rms_growth times its own fit error (or the noise there), and its centroid lies
//    within offset_allowance of the plane;
//  - pixel count and fit error (the paper's): only a segment with at least min_seed_pixels points
//    and its own fit error within the allowance starts a plane.
// A second pass joins merged planes, best pair first, while the plane fitted to both stays within
// the allowance and the RMS growth (and so does each part) and within the widened angle of both
// parts: it repairs planes that the first pass split because a noisy seed or a far, noisy surface
// stopped the growth. Planes that do not touch (a wall cut in two by an occluder) also join when
// nearly parallel, alike in colour, and not seen through (see the join_apart fields).
// Planes seen at more than max_incidence_deg from face-on (the surfaces of flying pixels along
// depth edges contain the camera centre) never seed. Neighbours are segments with 8-adjacent pixels
// (default) or, as in the paper, overlapping bounding rectangles. Deterministic: the order is fixed
// by size, then label.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/plane_fit.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "kartograf/segmentation/segment_graph.hpp"

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
  // Depth quantization step [m] at depth z: depth_step_per_z2 * z^2 (a structured-light sensor
  // quantizes disparity: z^2 / (f b s) for focal length f [px], baseline b [m] and 1/s pixel
  // disparity steps; Kinect: 1 / (525 * 0.075 * 8)). Half a step adds to the offset allowance:
  // a small piece of a slanted far surface can lie on one quantization level.
  double depth_step_per_z2 = 0.0032;
  double max_incidence_deg = 80.0;  // angle between the normal and the ray to the centroid
  bool join_planes = true;          // the second pass
  // The RMS distance of a joining piece to the plane (first pass: a segment with a fit; second
  // pass: the joint fit of two planes) stays within this multiple of the pieces' own RMS errors,
  // or within depth_noise there: a step or a crease shows here even when it hides within the
  // allowance.
  double max_joint_rms_growth = 2.0;
  // Also join planes that do not touch (a wall cut in two by a doorway or an occluder) when their
  // normals are within max_apart_angle_deg.
  bool join_apart = true;
  double max_apart_angle_deg = 10.0;
  std::uint64_t min_apart_pixels = 100;  // smaller planes only join planes they touch
  // ... and, when segment colours are given, when their mean CIE-Lab colours are within this
  // distance: two pieces of one surface look alike, while a door leaf flat on a wall or the walls
  // of two rooms in one plane seen through a doorway do not (measured: the two halves of the
  // table in PCL's mOSD test55 differ by 13 under uneven light; differently painted coplanar
  // walls of the synthetic world by 20 to 23).
  double max_apart_colour_distance = 18.0;
  // ... and, when the points are given and the camera sees through the joint plane (a point
  // behind it) at more than max_see_through_fraction of the valid pixels on the image line
  // between the two pieces, only when their colours are within max_see_through_colour_distance
  // (without colours: never). Behind an occluder a wall goes on; through a gap one sees either a
  // doorway in one wall, whose two sides keep the wall's exact colour, or two coplanar objects.
  double max_see_through_fraction = 0.25;
  double max_see_through_colour_distance = 6.0;
  PlaneFitParams fit;

  void validate() const;  // throws Error naming the first bad field
};

// The distance allowance at `point` (camera frame) for a plane with unit `normal`.
double distance_allowance(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                          const Eigen::Vector3d& normal);

// How far [m] the centroid of a piece at `point` may lie from a plane with unit `normal` it joins:
// offset_base (between touching pieces) + max_offset_fraction of the distance allowance + half a
// depth quantization step (along the ray, so scaled like the allowance).
double offset_allowance(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                        const Eigen::Vector3d& normal, bool touching);

// The depth-dependent part of the distance allowance at `point` for a plane with unit `normal`:
// distance_per_z2 z^2, scaled by the incidence like the allowance [m].
double depth_noise(const PlaneMergeParams& params, const Eigen::Vector3d& point,
                   const Eigen::Vector3d& normal);

// The angle [deg] by which depth noise at the plane's centroid can tilt its fitted normal:
// atan(depth_noise / half-width along the minor axis).
double normal_uncertainty_deg(const PlaneMergeParams& params, const SegmentPlane& plane);

struct MergedPlanes {
  std::vector<std::uint32_t> segment_plane;       // per segment: merged plane index or kNoLabel
  std::vector<geometry::SegmentMoments> moments;  // per merged plane: summed moments
  // Per merged plane: the sum of its segments' mean colours times their pixel counts (empty when
  // merge_segments was given no colours).
  std::vector<Eigen::Vector3d> colour_sums;
  std::vector<SegmentPlane> planes;  // per merged plane: the re-fit
  SegmentGraph graph;                // the segments' neighbours
};

// What merging may use besides the labels and moments (all optional).
struct MergeInputs {
  std::span<const Eigen::Vector3f> colours;  // each segment's mean CIE-Lab (planes apart)
  const PointImage* points = nullptr;        // the organized cloud of the labels (see-through)
  // The segments' neighbours when the caller knows them (the cells mode: cells and blocks next
  // to each other); otherwise found in the labels by params.neighbours.
  const SegmentGraph* graph = nullptr;
  // Each segment's fit_plane(its moments, moments.origin, params.fit) when the caller has it (the
  // cells mode fitted them to test planarity); otherwise fitted here.
  std::span<const SegmentPlane> fits = {};
  // Each segment's labelled pixels: sum of x, sum of y, count (where the see-through test draws
  // its lines from) when the caller knows them; otherwise summed over the labels.
  std::span<const Eigen::Vector3d> pixel_sums = {};
  // The segment at pixel (x, y) (kNoLabel: none) when the caller knows it without a label image
  // (the cells mode: each cell's or block's segment). With it, and with the graph and the pixel
  // sums, the labels are not read and may be an empty image.
  std::function<std::uint32_t(int x, int y)> segment_at = {};
};

// moments.segments and the label image (unless empty: see MergeInputs::segment_at) cover the same
// segment_count segments.
MergedPlanes merge_segments(const SegmentLabelImage& labels,
                            const geometry::SegmentMomentSet& moments,
                            const PlaneMergeParams& params, const MergeInputs& inputs = {});

}  // namespace kartograf::segmentation
