#pragma once
// Rule-based classification of regions into floor, wall, ceiling, door or unknown
// (docs/methods.md M2 step 3), and the whole pipeline from an organized point image to a
// SemanticImage.
//
// Rules (defaults are the paper's values where it gives them):
//  - floor: horizontal, facing up, within floor_tolerance of the floor height (the lowest large
//    horizontal region, gravity.hpp); several regions may be floor (furniture splits it);
//  - ceiling: horizontal, facing down, within ceiling_tolerance of the ceiling height, or higher
//    than door_max_height + reach_tolerance above the floor (a lowered part of a high ceiling);
//  - door: vertical, width in [door_min_width, door_max_width], reaching the floor (or cut below by
//    the view), its top at door_min_height..door_max_height above the floor (or cut above by the
//    view and at most door_max_height), at least half door_min_height of it in view, and next to
//    a wall region parallel to it that it stands door_min_wall_offset (more far away) to
//    door_max_wall_offset in front of (a door leaf standing open against the wall) or, its top
//    in view and at least door_min_lintel below the wall's, door_min_wall_offset to
//    door_max_recess behind (a closed door in its frame). "Next to":
//    adjacent, directly or through one region between (the leaf's edge face), or within
//    door_max_wall_gap along the wall (the wall behind a leaf is hidden by it);
//  - wall: vertical and, as in the paper, height >= wall_height_fraction x (ceiling - floor) and
//    width >= wall_min_width. Frames see parts of walls, so each test also passes when the view
//    explains its failure: the height test when the region reaches (or is cut by the view near)
//    both the floor and the ceiling level, or reaches the ceiling and is hidden below by a nearer
//    surface (occluded_below: furniture, or a scanner whose view starts at its own height); the
//    width test when the region is cut sideways by the view, is adjacent to another wall, or
//    (reaching the ceiling) is hidden sideways by a nearer surface. Without a ceiling in view the
//    room height is assumed_room_height above the floor; without a floor, below the ceiling - but
//    the sensor (height 0) always lies between the two. A vertical region
//    next to a wall and reaching above door_min_height is a wall too (door jambs, wall pieces
//    between doors), as is a vertical region of at least coplanar_wall_min_area in a wall's plane
//    and within coplanar_wall_gap of it along the wall (wall below a window band, between
//    shelves);
//  - a horizontal region facing down below the ceiling and adjacent to a wall (a lintel's
//    underside) is wall;
//  - everything else, and pixels in no region, unknown (furniture included: M2 has no furniture
//    rule).
#include <span>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/semantic/gravity.hpp"
#include "kartograf/semantic/normals_image.hpp"
#include "kartograf/semantic/regions.hpp"

namespace kartograf::semantic {

struct ClassificationParams {
  double floor_tolerance = 0.10;    // m
  double ceiling_tolerance = 0.10;  // m
  double wall_height_fraction = 0.9;
  double wall_min_width = 2.0;                          // m
  double reach_tolerance = 0.25;                        // m: "reaches the floor/ceiling level"
  double assumed_room_height = 2.5;                     // m
  double door_min_height = 1.8, door_max_height = 2.3;  // m
  double door_min_width = 0.6, door_max_width = 1.2;    // m
  // A leaf stands door_min_wall_offset (or door_relative_wall_offset x its range, as depth noise
  // grows) to door_max_wall_offset in front of its wall: not a piece of the wall itself.
  double door_min_wall_offset = 0.03;  // m
  double door_relative_wall_offset = 0.01;
  double door_max_wall_gap = 0.5;  // m along the wall between a leaf and its wall's visible part
  double door_max_wall_offset = 0.09;  // m: a leaf is ~5 cm out; a wall step (thickness) >= 10 cm
  // A closed door stands in its frame up to door_max_recess behind its wall's face (a wall's
  // thickness), its top in view with the wall going on at least door_min_lintel above it.
  double door_max_recess = 0.30;  // m
  double door_min_lintel = 0.10;  // m
  double parallel_tolerance_deg = 15.0;
  // A vertical region in a wall's plane (within coplanar_wall_offset, below a door leaf's 3 cm)
  // and within coplanar_wall_gap of it along the wall is that wall, whatever its height.
  double coplanar_wall_offset = 0.025;   // m
  double coplanar_wall_gap = 1.0;        // m
  double coplanar_wall_min_area = 0.05;  // m^2
  // Furniture (tables, chairs, beds, cabinets, shelves): what is left that stands on the floor
  // and ends below the ceiling: a horizontal face (a top, a seat, a shelf board) from
  // furniture_min_height to furniture_max_height above the floor, a vertical face from the floor
  // (or hidden there) up to at most furniture_max_height, its top in view (not cut by the image,
  // nor hidden by a surface more than shelf_max_depth before it with its plane seen again above
  // that: the wall between a table's legs), and what joins them within that height.
  // At most furniture_max_width wide: a longer face is part of the room (a wall seen in part).
  double furniture_min_height = 0.15;  // m
  double furniture_max_height = 2.1;   // m
  double furniture_max_width = 2.5;    // m
  // A face whose top is hidden by a surface standing at most this far before it (along its
  // normal) may be a shelf's back below a board, and stays a furniture face; further before it
  // (a table's edge before the wall between its legs: 1.4-1.9 m on survey seed 12), the face is
  // furniture only where its plane is not seen again above (bookcases are 0.25-0.45 m deep).
  double shelf_max_depth = 0.5;  // m
};

// Classes per region (index = label - 1).
std::vector<SemanticClass> classify_regions(std::span<const RegionMeasurements> regions,
                                            const GravityEstimate& gravity,
                                            const ClassificationParams& params = {});

struct LabellingParams {
  NormalsImageParams normals;
  RegionParams regions;
  CoplanarMergeParams merge;
  LayerSplitParams layers;
  MeasureParams measure;
  GravityParams gravity;
  ClassificationParams classes;
};

struct SemanticLabelling {
  NormalImage normals;
  RegionSegmentation regions;
  std::vector<RegionMeasurements> measurements;
  GravityEstimate gravity;
  std::vector<SemanticClass> region_classes;
  SemanticImage semantic;
};

// Whether the points are a camera frame in the optical convention (x right, y down, z ahead):
// every point in front (z > 0) and x/z, y/z linear in column and row (a pinhole projection; a
// laser scan's equal angle steps are not).
bool is_camera_frame(const PointImage& points);

// The whole of M2 steps 1-3 on one organized point image (sensor at the origin): smoothing,
// normals, region growing, layer splitting (on the smoothed points), gravity, measurements,
// classification; a split-off layer the rules leave unknown takes the class of its parent.
// Without a gravity prior, a camera frame (is_camera_frame) gets up = -y: an upright camera.
SemanticLabelling label_organized_points(const compute::Context& context, const PointImage& points,
                                         const LabellingParams& params = {});

}  // namespace kartograf::semantic
