// The semantic grid's free space from the views' rays: scenes of boxes seen by a depth camera
// (rays cast from each view's origin, grazing returns dropped as a Kinect drops them) show that
// the floor under a table whose top no view returned is furniture while the floor beside it is
// free, that a table's edges taken for walls are furniture, and that a hull spanning open floor
// leaves it floor. Without the views' origins the grid cannot tell these apart.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/semantic/semantic_grid.hpp"
#include "test_support_core.hpp"

namespace kartograf::semantic {
namespace {

using C = SemanticClass;

// An axis-aligned box whose top face (+z) and sides return the given classes.
struct Box {
  Eigen::Vector3d lo, hi;
  SemanticClass top, sides;
};

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  int axis = 0;  // of the face entered
  const Box* box = nullptr;
};

// Where the ray origin + t d enters `box` (slab method), if it does in front of the origin.
std::optional<Hit> enter(const Box& box, const Eigen::Vector3d& origin, const Eigen::Vector3d& d) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  int axis = -1;
  for (int k = 0; k < 3; ++k) {
    if (std::fabs(d[k]) < 1e-12) {
      if (origin[k] < box.lo[k] || origin[k] > box.hi[k]) return std::nullopt;
      continue;
    }
    double a = (box.lo[k] - origin[k]) / d[k], b = (box.hi[k] - origin[k]) / d[k];
    if (a > b) std::swap(a, b);
    if (a > t0) t0 = a, axis = k;
    t1 = std::min(t1, b);
  }
  if (t0 > t1 || axis < 0) return std::nullopt;
  return Hit{t0, axis, &box};
}

struct Views {
  std::vector<Eigen::Vector3d> points;
  std::vector<SemanticClass> labels;
  std::vector<std::uint32_t> ids;
  std::vector<Eigen::Vector3d> origins;
};

constexpr double kStep = 0.25 * std::numbers::pi / 180;  // a 320-pixel-wide view's spacing

// A structured-light camera's depth step: returns beyond `beyond` metres come back `short_by`
// nearer along the ray (its disparity is quantised: steps of about z^2 / 315 m, 5 cm at 4 m).
struct DepthStep {
  double beyond = std::numeric_limits<double>::infinity(), short_by = 0;
};

// Each origin looks all round (0.25 degree steps, 60 degrees down to 5 up); returns more grazing
// than 75 degrees from a face's normal are dropped, as a structured-light camera drops them. With
// `mixed_pixels`, a return more than 0.3 m beyond the one below it in the view (an object's top
// outline against what lies behind) is preceded by a mixed pixel, halfway, labelled unknown, as
// a depth camera returns them at depth edges.
Views look(const std::vector<Box>& scene, const std::vector<Eigen::Vector3d>& origins,
           const DepthStep& step = {}, bool mixed_pixels = false) {
  Views v;
  const double grazing = std::cos(75.0 * std::numbers::pi / 180);
  for (const Eigen::Vector3d& origin : origins) {
    for (int az = 0; az < 4 * 360; ++az) {
      double below = std::numeric_limits<double>::infinity();  // the last return's range
      for (int el = -4 * 60; el <= 4 * 5; ++el) {
        const double a = az * kStep, e = el * kStep;
        const Eigen::Vector3d d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
        Hit nearest;
        for (const Box& box : scene) {
          const std::optional<Hit> hit = enter(box, origin, d);
          if (hit && hit->t < nearest.t) nearest = *hit;
        }
        if (!nearest.box || std::fabs(d[nearest.axis]) < grazing) continue;
        const double t = nearest.t > step.beyond ? nearest.t - step.short_by : nearest.t;
        for (const double f : {0.2, 0.35, 0.5, 0.65, 0.8}) {
          if (!mixed_pixels || !(t > below + 0.3)) break;
          v.points.push_back(origin + ((1 - f) * below + f * t) * d);
          v.labels.push_back(C::unknown);
          v.ids.push_back(static_cast<std::uint32_t>(v.origins.size()));
        }
        below = t;
        v.points.push_back(origin + t * d);
        v.labels.push_back(nearest.axis == 2 ? nearest.box->top : nearest.box->sides);
        v.ids.push_back(static_cast<std::uint32_t>(v.origins.size()));
      }
    }
    v.origins.push_back(origin);
  }
  return v;
}

// A 5 x 4 m room: floor and four walls 2.5 m high.
std::vector<Box> room() {
  return {{{0, 0, -0.05}, {5, 4, 0}, C::floor, C::floor},
          {{-0.1, -0.1, 0}, {0, 4.1, 2.5}, C::wall, C::wall},
          {{5, -0.1, 0}, {5.1, 4.1, 2.5}, C::wall, C::wall},
          {{0, -0.1, 0}, {5, 0, 2.5}, C::wall, C::wall},
          {{0, 4, 0}, {5, 4.1, 2.5}, C::wall, C::wall}};
}

// Every ray of these views: a sweep at 0.25 degree steps is as dense as a 320-pixel view, and the
// grid's default (every 4th ray) is set for views that overlap as a sequence's do.
SemanticGridParams every_ray() {
  SemanticGridParams p;
  p.free_space_ray_stride = 1;
  return p;
}

SemanticClass class_at(const SemanticGrid& grid, double x, double y) {
  const Eigen::Vector2i c = grid.cell_of({x, y});
  return grid.classes(c.x(), c.y());
}

// Six places at 1 m height around the 5 x 4 m room, over 1 m from its middle.
std::vector<Eigen::Vector3d> six_places() {
  return {{0.8, 0.5, 1}, {4.4, 0.5, 1}, {4.4, 3.5, 1}, {0.8, 3.5, 1}, {0.6, 2.0, 1}, {4.6, 2.0, 1}};
}

// The room with a 1.2 x 0.8 m table in it (top 0.72-0.76 m, 5 cm legs): its top's sides return
// "wall", its legs unknown.
std::vector<Box> room_with_a_table() {
  std::vector<Box> scene = room();
  scene.push_back({{2.0, 1.6, 0.72}, {3.2, 2.4, 0.76}, C::unknown, C::wall});
  for (const double x : {2.04, 3.11})
    for (const double y : {1.64, 2.31})
      scene.push_back({{x, y, 0}, {x + 0.05, y + 0.05, 0.72}, C::unknown, C::unknown});
  return scene;
}

// Of the cells whose centres lie in [x0, x1) x [y0, y1) (centres 0.05 m apart from x0, y0): how
// many are of class `c`, and how many there are.
std::pair<int, int> cells_of_class(const SemanticGrid& grid, SemanticClass c, double x0, double x1,
                                   double y0, double y1) {
  int of_class = 0, cells = 0;
  for (double x = x0; x < x1; x += 0.05) {
    for (double y = y0; y < y1; y += 0.05) {
      of_class += class_at(grid, x, y) == c;
      ++cells;
    }
  }
  return {of_class, cells};
}

// A 5 x 4 m room with a 1.2 x 0.8 m table (top 0.72-0.76 m, 5 cm legs) seen from six places at
// 1 m height, all over 1 m from it: its top is too grazing to return, its edges come back as
// "wall" (as the views label a 4 cm strip cut by the image), its legs as unknown.
Views table_seen_from_six_places(bool mixed_pixels) {
  return look(room_with_a_table(), six_places(), {}, mixed_pixels);
}

TEST(SemanticGridFreeSpace, TheFloorUnderATableWhoseTopNoViewReturnedIsFurniture) {
  const Views v = table_seen_from_six_places(false);
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 2.6, 2.0), C::furniture);   // under the middle of the top
  EXPECT_EQ(class_at(grid, 2.1, 1.7), C::furniture);   // under a corner
  EXPECT_EQ(class_at(grid, 2.01, 2.0), C::furniture);  // the west edge, returned as wall
  EXPECT_EQ(class_at(grid, 2.6, 1.3), C::floor);       // 0.3 m beside it
  EXPECT_EQ(class_at(grid, 1.6, 2.0), C::floor);
  EXPECT_EQ(class_at(grid, 3.6, 2.0), C::floor);

  // Without the origins the edges are walls around floor.
  const SemanticGrid blind = build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids);
  EXPECT_EQ(class_at(blind, 2.01, 2.0), C::wall);
  EXPECT_EQ(class_at(blind, 2.6, 2.0), C::floor);
}

// A cabinet (1 x 0.5 m, 0.7 m high) whose sides the views label wall (vertical faces standing
// on the floor, as a cabinet's front is labelled) and whose top they label furniture. Walls reach
// the ceiling; the views saw through these sides' cells just above their top: they are the
// cabinet's, and furniture with it. The room's walls stay walls. Without the origins the sides are
// walls.
void expect_a_cabinet_not_walls(double height) {
  std::vector<Box> scene = room();
  scene.push_back({{2.0, 1.5, 0}, {3.0, 2.0, height}, C::furniture, C::wall});
  const Views v = look(scene, six_places());
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 2.01, 1.75), C::furniture);  // the west side
  EXPECT_EQ(class_at(grid, 2.99, 1.75), C::furniture);  // the east side
  EXPECT_EQ(class_at(grid, 2.5, 1.51), C::furniture);   // the south side
  EXPECT_EQ(class_at(grid, 2.5, 1.75), C::furniture);   // the top
  EXPECT_EQ(class_at(grid, 2.5, 1.2), C::floor);
  EXPECT_EQ(class_at(grid, -0.025, 2.0), C::wall);  // the room's walls
  EXPECT_EQ(class_at(grid, 2.5, 4.025), C::wall);
  EXPECT_EQ(class_at(grid, 5.025, 2.0), C::wall);

  const SemanticGrid blind = build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids);
  EXPECT_EQ(class_at(blind, 2.01, 1.75), C::wall);
}

TEST(SemanticGridFreeSpace, WallCellsSeenThroughAboveTheirTopAreALowCabinets) {
  expect_a_cabinet_not_walls(0.7);
}

// The same cabinet 1.1 m high, its top above the views' eyes (1 m): the rays that cross just
// above it rise from across the room, fewer than below the eyes, but they do.
TEST(SemanticGridFreeSpace, ACabinetTallerThanTheViewsEyesIsNoWall) {
  expect_a_cabinet_not_walls(1.1);
}

// Furniture cells inside the room (0.25 m from its walls) and over 0.1 m from the table of the
// tests below (x 2.0-3.2, y 1.6-2.4).
int furniture_off_the_table(const SemanticGrid& grid) {
  int count = 0;
  for (double x = 0.275; x < 4.75; x += 0.05) {
    for (double y = 0.275; y < 3.75; y += 0.05) {
      const bool near_table = x > 1.9 && x < 3.3 && y > 1.5 && y < 2.5;
      count += !near_table && class_at(grid, x, y) == C::furniture;
    }
  }
  return count;
}

// The table above, its outline's mixed pixels floating behind it (a fan beyond each edge, from
// every view). They are crossed by the rays of the views that see past the table: phantoms, and
// the floor around the table stays floor. With the phantoms kept (phantom_pass_ratio 0) they
// make furniture of cells all over the room. The floor-point guard (min_obstacle_floor_ratio),
// which these few views' dense floor would pass, is off: on a sequence the mixed pixels of
// hundreds of views pile up in the same cells.
TEST(SemanticGridFreeSpace, MixedPixelsBehindATableMakeNoObstacle) {
  const Views v = table_seen_from_six_places(true);
  SemanticGridParams params = every_ray();
  params.min_obstacle_floor_ratio = 0;
  const SemanticGrid grid = build_semantic_grid(v.points, v.labels, params, {}, v.ids, v.origins);
  SemanticGridParams kept = params;
  kept.phantom_pass_ratio = 0;
  const SemanticGrid phantoms = build_semantic_grid(v.points, v.labels, kept, {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 2.6, 2.0), C::furniture);  // the table stays
  EXPECT_EQ(class_at(grid, 2.1, 1.7), C::furniture);
  EXPECT_EQ(furniture_off_the_table(grid), 0);
  EXPECT_GT(furniture_off_the_table(phantoms), 50);
}

// Four tables like the one above in a 2 x 2 block, 0.6 m apart, in a 7 x 6 m room: closed over
// the 0.75 m join gap their outlines are one piece of 6.6 m^2, too large for furniture; judged
// again over 0.35 m gaps each table is filled, and the aisles between them stay floor.
TEST(SemanticGridFreeSpace, TablesTooCloseToTellApartAtTheJoinGapAreJudgedOneByOne) {
  std::vector<Box> scene = {{{0, 0, -0.05}, {7, 6, 0}, C::floor, C::floor},
                            {{-0.1, -0.1, 0}, {0, 6.1, 2.5}, C::wall, C::wall},
                            {{7, -0.1, 0}, {7.1, 6.1, 2.5}, C::wall, C::wall},
                            {{0, -0.1, 0}, {7, 0, 2.5}, C::wall, C::wall},
                            {{0, 6, 0}, {7, 6.1, 2.5}, C::wall, C::wall}};
  for (const double x0 : {2.0, 3.8}) {
    for (const double y0 : {1.9, 3.3}) {
      scene.push_back({{x0, y0, 0.72}, {x0 + 1.2, y0 + 0.8, 0.76}, C::unknown, C::wall});
      for (const double x : {x0 + 0.04, x0 + 1.11})
        for (const double y : {y0 + 0.04, y0 + 0.71})
          scene.push_back({{x, y, 0}, {x + 0.05, y + 0.05, 0.72}, C::unknown, C::unknown});
    }
  }
  const Views v = look(scene, {{0.8, 0.6, 1},
                               {6.2, 0.6, 1},
                               {6.2, 5.4, 1},
                               {0.8, 5.4, 1},
                               {0.6, 3.0, 1},
                               {6.4, 3.0, 1},
                               {3.5, 0.6, 1},
                               {3.5, 5.4, 1}});
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  for (const double x : {2.6, 4.4}) {
    for (const double y : {2.3, 3.7}) {
      EXPECT_EQ(class_at(grid, x, y), C::furniture) << "the table at " << x << ", " << y;
    }
  }
  EXPECT_EQ(class_at(grid, 3.5, 2.3), C::floor);  // the aisles between them
  EXPECT_EQ(class_at(grid, 2.6, 3.0), C::floor);
}

// An L of two low benches (0.45 m): the convex hull of the piece spans the open floor in the L's
// corner, which the views saw through at every height below the benches' top: it stays floor.
// Without the origins the hull makes it furniture.
TEST(SemanticGridFreeSpace, AHullOverOpenFloorLeavesItFloor) {
  std::vector<Box> scene = room();
  scene.push_back({{1.0, 1.0, 0}, {2.6, 1.3, 0.45}, C::furniture, C::furniture});
  scene.push_back({{1.0, 1.3, 0}, {1.3, 2.8, 0.45}, C::furniture, C::furniture});
  const Views v = look(
      scene,
      {{2.6, 2.6, 1}, {3.8, 3.2, 1}, {4.2, 0.5, 1}, {0.4, 3.5, 1}, {2.0, 3.4, 1}, {3.4, 1.8, 1}});
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 1.8, 1.15), C::furniture);  // the benches
  EXPECT_EQ(class_at(grid, 1.15, 2.0), C::furniture);
  EXPECT_EQ(class_at(grid, 1.7, 1.7), C::floor);  // the open corner inside the hull
  EXPECT_EQ(class_at(grid, 1.5, 2.0), C::floor);

  const SemanticGrid blind = build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids);
  EXPECT_EQ(class_at(blind, 1.7, 1.7), C::furniture);
}

// The table above and, 0.65 m north of it, a cabinet 1.3 m high (above the views' eyes), larger
// than the table: one piece over the join gap, whose tops are mostly the cabinet's. The floor
// between them lies in the table's shadow for the views from the south (a band of heights under
// its top, lower the farther from it) and in the cabinet's for those from the north: seen through
// above the table's top, not at every height below the cabinet's. Beyond the shadow of the
// table's own top (0.35 m from it) it stays floor; the table and the cabinet are furniture.
TEST(SemanticGridFreeSpace, FloorBetweenATableAndATallerCabinetStaysFloor) {
  std::vector<Box> scene = room_with_a_table();
  scene.push_back({{1.9, 3.05, 0}, {3.3, 3.45, 1.3}, C::furniture, C::furniture});
  const Views v =
      look(scene, {{0.8, 0.5, 1}, {4.4, 0.5, 1}, {2.6, 0.4, 1}, {1.2, 3.7, 1}, {4.0, 3.7, 1}});
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 2.6, 2.0), C::furniture);  // the table
  EXPECT_EQ(class_at(grid, 2.1, 1.7), C::furniture);
  EXPECT_EQ(class_at(grid, 2.6, 3.04), C::furniture);  // the cabinet's front
  const auto [floor, cells] = cells_of_class(grid, C::floor, 2.125, 3.1, 2.775, 2.99);
  EXPECT_GE(floor, cells * 9 / 10) << floor << " of " << cells << " cells between them";
}

// The table above and, 0.35 m north of it, a cabinet 0.9 m high (below the views' eyes), larger
// than the table: one piece over the join gap, whose tops, median and 90th percentile, are the
// cabinet's. The views saw through the table's cells under the cabinet's top; under the table's
// own top (the level of a third of the piece's tops) they did not: the floor under the table is
// furniture, and beside the table it stays floor.
TEST(SemanticGridFreeSpace, ATableJoinedToATallerCabinetIsJudgedAtItsOwnTop) {
  std::vector<Box> scene = room_with_a_table();
  scene.push_back({{1.4, 2.75, 0}, {3.8, 3.25, 0.9}, C::furniture, C::furniture});
  const Views v = look(scene, six_places());
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  const auto [furniture, cells] = cells_of_class(grid, C::furniture, 2.125, 3.1, 1.725, 2.3);
  EXPECT_GE(furniture, cells * 9 / 10) << furniture << " of " << cells << " cells under the table";
  EXPECT_EQ(class_at(grid, 1.5, 2.0), C::floor);       // beside the table
  EXPECT_EQ(class_at(grid, 2.6, 2.74), C::furniture);  // the cabinet's front
}

// A 1.6 x 0.9 m table (top 0.72-0.76 m) whose top returns nothing the grid counts as an obstacle
// (its faces labelled floor, a bad label far from the floor: as its edges are where the views
// lose them), on four 5 cm legs labelled unknown, with or without its top. Its legs stand 1.5 m
// apart along it: more than the join gap, so the fill joins them in pairs only. The floor-point
// guard (min_obstacle_floor_ratio) is off: these sweeps put thousands of floor points around a
// 5 cm leg in its cells, where a sequence's views, a few hundred points each, leave the legs
// obstacles.
std::vector<Box> legs_of_a_long_table(bool with_top) {
  std::vector<Box> scene = room();
  if (with_top) scene.push_back({{1.7, 1.55, 0.72}, {3.3, 2.45, 0.76}, C::floor, C::floor});
  for (const double x : {1.725, 3.225})  // across a cell boundary: a leg inside one cell is a speck
    for (const double y : {1.575, 2.375})
      scene.push_back({{x, y, 0}, {x + 0.05, y + 0.05, 0.72}, C::unknown, C::unknown});
  return scene;
}

// Under a top no ray passed through, the floor between the four legs is furniture; beside the
// table it stays floor.
TEST(SemanticGridFreeSpace, ATableSeenOnlyByItsLegsIsFurniture) {
  const Views v = look(legs_of_a_long_table(true), six_places());
  SemanticGridParams params = every_ray();
  params.min_obstacle_floor_ratio = 0;
  const SemanticGrid grid = build_semantic_grid(v.points, v.labels, params, {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 2.5, 2.0), C::furniture);  // under the middle of the top
  EXPECT_EQ(class_at(grid, 2.0, 1.7), C::furniture);
  EXPECT_EQ(class_at(grid, 3.0, 2.3), C::furniture);
  EXPECT_EQ(class_at(grid, 2.5, 1.3), C::floor);  // 0.25 m beside it
  EXPECT_EQ(class_at(grid, 1.4, 2.0), C::floor);
  EXPECT_EQ(grid.inferred.tables_on_legs, 1);
  EXPECT_EQ(grid.inferred.fill_cells_trimmed_at_tables, 0);  // no fill joined to it
}

// The same four posts with no top: the rays crossed the floor between them at the posts' height
// as they crossed the floor around them, and it stays floor.
TEST(SemanticGridFreeSpace, FourPostsWithNoTopLeaveTheFloorBetweenThemFree) {
  const Views v = look(legs_of_a_long_table(false), six_places());
  SemanticGridParams params = every_ray();
  params.min_obstacle_floor_ratio = 0;
  const SemanticGrid grid = build_semantic_grid(v.points, v.labels, params, {}, v.ids, v.origins);
  EXPECT_EQ(class_at(grid, 2.5, 2.0), C::floor);
  EXPECT_EQ(class_at(grid, 2.5, 1.7), C::floor);
  EXPECT_EQ(grid.inferred.tables_on_legs, 0);
}

// Points as three views pooled them, view after view, without the views' origins: dense for
// surfaces (points on a lattice over a box, in each view), sparse for a depth edge's mixed pixels
// (one point a view).
struct Pooled {
  std::array<std::vector<Eigen::Vector3d>, 3> views;
  std::array<std::vector<SemanticClass>, 3> view_labels;

  void box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, SemanticClass label,
           double step = 0.01) {
    for (double x = lo.x(); x <= hi.x() + 1e-9; x += step)
      for (double y = lo.y(); y <= hi.y() + 1e-9; y += step)
        for (double z = lo.z(); z <= hi.z() + 1e-9; z += step) add({x, y, z}, label);
  }
  void add(const Eigen::Vector3d& p, SemanticClass label) {
    for (std::size_t view = 0; view < views.size(); ++view) {
      views[view].push_back(p);
      view_labels[view].push_back(label);
    }
  }
  Views merged() const {
    Views v;
    for (std::size_t view = 0; view < views.size(); ++view) {
      v.points.insert(v.points.end(), views[view].begin(), views[view].end());
      v.labels.insert(v.labels.end(), view_labels[view].begin(), view_labels[view].end());
      v.ids.insert(v.ids.end(), views[view].size(), static_cast<std::uint32_t>(view));
    }
    return v;
  }
};

// A table whose top the views dropped and whose far edge they did not see (its near edge and
// four legs) and, 1 m north of it, a cabinet 3.8 m long, joined by a line of a depth edge's mixed
// pixels on the floor between them (one point a view in each cell, from a far leg to 0.2 m from
// the cabinet): closed over the join gap, one piece too large for furniture. Closed over the
// smaller gap the table's far legs stand apart from its near edge, and only the near edge's strip
// was filled (survey seed 2); judged again without the mixed pixels, the table is one piece, and
// filled. Without the views' origins the fill is the piece's hull.
TEST(SemanticGridFreeSpace, MixedPixelsDoNotJoinATableToItsNeighbours) {
  Pooled pooled;
  pooled.box({0, 0, 0}, {5, 4.5, 0}, C::floor, 0.025);
  pooled.box({2.0, 1.6, 0.72}, {3.2, 1.63, 0.76}, C::unknown);  // the near edge
  for (const double x : {2.0, 3.1})
    for (const double y : {1.6, 2.3})
      pooled.box({x, y, 0.1}, {x + 0.1, y + 0.1, 0.72}, C::unknown, 0.02);
  pooled.box({0.6, 3.4, 0.1}, {4.4, 3.9, 0.9}, C::furniture, 0.05);
  for (double y = 2.425; y < 3.2; y += 0.05) pooled.add({3.175, y, 0.4}, C::unknown);
  SemanticGridParams params;
  params.min_obstacle_floor_ratio = 0;
  const Views v = pooled.merged();
  const SemanticGrid grid = build_semantic_grid(v.points, v.labels, params, {}, v.ids);
  EXPECT_EQ(class_at(grid, 2.6, 1.62), C::furniture);  // the near edge
  EXPECT_EQ(class_at(grid, 2.6, 2.0), C::furniture);   // under the top
  EXPECT_EQ(class_at(grid, 2.3, 2.2), C::furniture);
  EXPECT_EQ(class_at(grid, 1.5, 2.0), C::floor);  // beside the table
}

// A post 3 cm across inside one cell (a chair's leg), solid from the floor up in three views, has
// no obstacle beside it and stays one: a robot must not drive into it. A speck of points 0.4-0.5 m
// up, standing on nothing, is removed as before.
TEST(SemanticGridFreeSpace, ALonePostInsideOneCellStaysAnObstacle) {
  Pooled pooled;
  pooled.box({0, 0, 0}, {3, 3, 0}, C::floor, 0.025);
  pooled.box({1.51, 1.51, 0.02}, {1.54, 1.54, 0.7}, C::furniture);
  pooled.box({2.01, 1.01, 0.4}, {2.04, 1.04, 0.5}, C::unknown);
  SemanticGridParams params;
  params.min_obstacle_floor_ratio = 0;
  const Views v = pooled.merged();
  const SemanticGrid grid = build_semantic_grid(v.points, v.labels, params, {}, v.ids);
  EXPECT_EQ(class_at(grid, 1.525, 1.525), C::furniture);
  EXPECT_EQ(grid.weight(grid.cell_of({1.525, 1.525}).x(), grid.cell_of({1.525, 1.525}).y()), 0.0f);
  EXPECT_EQ(class_at(grid, 2.025, 1.025), C::floor);
  EXPECT_EQ(class_at(grid, 1.575, 1.525), C::floor);  // beside the post
  EXPECT_EQ(grid.inferred.lone_posts_kept, 1);
}

// Two views 4.4 m from the room's east wall (x = 5) read it 8 cm short, as a depth step does: a
// layer of wall points a cell in front of it, with a cell of floor between. Three views nearby
// see through that layer at every height: it is floor, and the wall behind it stays wall.
// Without the origins, or with the option off, the layer is a wall of its own.
TEST(SemanticGridFreeSpace, AFarWallsLayerThatNearerViewsSeeThroughIsFloor) {
  const std::vector<Eigen::Vector3d> far{{0.6, 1.2, 1}, {0.6, 2.8, 1}};
  const std::vector<Eigen::Vector3d> near{{4.0, 1.0, 1}, {4.0, 3.0, 1}, {2.5, 2.0, 1}};
  Views v = look(room(), far, {3.5, 0.08});
  const Views close = look(room(), near);
  for (std::size_t i = 0; i < close.points.size(); ++i) {
    v.points.push_back(close.points[i]);
    v.labels.push_back(close.labels[i]);
    v.ids.push_back(close.ids[i] + static_cast<std::uint32_t>(far.size()));
  }
  v.origins.insert(v.origins.end(), near.begin(), near.end());
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  for (const double y : {1.5, 2.0, 2.5}) {
    EXPECT_EQ(class_at(grid, 4.925, y), C::floor) << "the layer at y " << y;
    EXPECT_EQ(class_at(grid, 4.975, y), C::floor) << "the cell between at y " << y;
    EXPECT_EQ(class_at(grid, 5.025, y), C::wall) << "the wall at y " << y;
  }

  SemanticGridParams off = every_ray();
  off.seen_through_wall_range = 0;
  const SemanticGrid layered = build_semantic_grid(v.points, v.labels, off, {}, v.ids, v.origins);
  EXPECT_EQ(class_at(layered, 4.925, 2.0), C::wall);
  const SemanticGrid blind = build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids);
  EXPECT_EQ(class_at(blind, 4.925, 2.0), C::wall);
}

// Views along the room's east wall (x = 5), and a few of its points spilled into the cell in front
// of it for a metre (y 1.5-2.5), as a depth camera's noise spreads a face: the cell holds the
// floor the views saw there and rays cross it at every height, beside the wall's own cells with a
// hundred times its points. It is the face's spill: floor, and the wall stays wall. The faces'
// placement, which frees such cells when their points lie on the cell boundary, is off. Without
// the rule (face_spill_ratio 0) or the origins they are wall.
TEST(SemanticGridFreeSpace, AWallFacesSpillIntoTheCellInFrontIsFloor) {
  std::vector<Eigen::Vector3d> places = six_places();
  for (const double y : {0.9, 1.6, 2.4, 3.1}) places.push_back({4.75, y, 1});
  Views v = look(room(), places);
  for (double y = 1.5; y < 2.5; y += 0.025) {
    for (double z = 0.12; z < 1.4; z += 0.1) {
      v.points.push_back({4.975, y, z});
      v.labels.push_back(C::wall);
      v.ids.push_back(v.points.size() % 2 == 0 ? 6 : 7);
    }
  }
  SemanticGridParams params = every_ray();
  params.min_obstacle_floor_ratio = 0;
  params.place_wall_faces = false;
  const SemanticGrid grid = build_semantic_grid(v.points, v.labels, params, {}, v.ids, v.origins);
  for (const double y : {1.7, 2.0, 2.3}) {
    EXPECT_EQ(class_at(grid, 4.975, y), C::floor) << "the spill at y " << y;
    EXPECT_EQ(class_at(grid, 5.025, y), C::wall) << "the wall at y " << y;
  }
  SemanticGridParams off = params;
  off.face_spill_ratio = 0;
  const SemanticGrid kept = build_semantic_grid(v.points, v.labels, off, {}, v.ids, v.origins);
  EXPECT_EQ(class_at(kept, 4.975, 2.0), C::wall);
  const SemanticGrid blind = build_semantic_grid(v.points, v.labels, params, {}, v.ids);
  EXPECT_EQ(class_at(blind, 4.975, 2.0), C::wall);
}

// Views from the room's west end (x = 0.6) drop the floor more than 3.7 m off, too grazing to
// return, but see the east wall (x = 5) down to its foot, and their rays to it pass low over that
// floor: the cells they crossed at every observable height from the band's bottom up are floor.
// Behind a 0.3 m crate the rays pass above 0.25 m only, and those cells stay unknown. Without the
// rule (or the origins) the strip along the wall is unknown: it is no hole in seen floor.
TEST(SemanticGridFreeSpace, TheFloorTheRaysCrossLowIsFloor) {
  std::vector<Box> scene = room();
  scene.push_back({{4.3, 1.6, 0}, {4.7, 2.4, 0.3}, C::furniture, C::furniture});
  const std::vector<Eigen::Vector3d> west_end{{0.6, 1.2, 1}, {0.6, 2.8, 1}};
  const Views v = look(scene, west_end);
  const SemanticGrid grid =
      build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  const auto unobserved_at = [](const SemanticGrid& g, double x, double y) {
    const Eigen::Vector2i c = g.cell_of({x, y});
    return std::isnan(g.weight(c.x(), c.y()));
  };
  for (const double y : {0.6, 1.0, 3.0, 3.4}) {
    EXPECT_EQ(class_at(grid, 4.725, y), C::floor) << "the floor before the wall at y " << y;
    EXPECT_EQ(class_at(grid, 5.025, y), C::wall) << "the wall at y " << y;
  }
  EXPECT_NE(class_at(grid, 4.825, 2.0), C::floor) << "behind the crate";
  EXPECT_NE(class_at(grid, 4.5, 2.0), C::floor) << "the crate";
  EXPECT_GT(grid.inferred.floor_seen_through, 0);

  SemanticGridParams off = every_ray();
  off.floor_seen_through = false;
  const SemanticGrid unseen = build_semantic_grid(v.points, v.labels, off, {}, v.ids, v.origins);
  EXPECT_TRUE(unobserved_at(unseen, 4.725, 1.0));
  EXPECT_EQ(unseen.inferred.floor_seen_through, 0);
  const SemanticGrid blind = build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids);
  EXPECT_TRUE(unobserved_at(blind, 4.725, 1.0));
}

// A pit 0.3 m deep before the east wall (x 4.3-4.9, y 1.6-2.4: stairs down, a sunken floor), seen
// from the west end and from 1.2 m before it: its far part returns its bottom, below the floor, its
// near part (under the rim) nothing, and rays to the wall pass low over both, as over floor lost
// at grazing angles; the seen floor encloses it. No floor fill takes it. The same views of a flat
// floor there make those cells floor.
TEST(SemanticGridFreeSpace, ADropInTheFloorIsNoFloor) {
  const auto scene = [](bool pit) {
    std::vector<Box> boxes = room();
    boxes.front() = {{0, 0, -0.4}, {4.3, 4, 0}, C::floor, C::unknown};
    boxes.push_back({{4.9, 0, -0.4}, {5, 4, 0}, C::floor, C::unknown});
    boxes.push_back({{4.3, 0, -0.4}, {4.9, 1.6, 0}, C::floor, C::unknown});
    boxes.push_back({{4.3, 2.4, -0.4}, {4.9, 4, 0}, C::floor, C::unknown});
    boxes.push_back({{4.3, 1.6, -0.4}, {4.9, 2.4, pit ? -0.3 : 0.0}, C::floor, C::unknown});
    return boxes;
  };
  const std::vector<Eigen::Vector3d> places{{0.6, 1.2, 1}, {0.6, 2.8, 1}, {3.1, 2.0, 1}};
  const auto grid_of = [&](bool pit) {
    const Views v = look(scene(pit), places);
    return build_semantic_grid(v.points, v.labels, every_ray(), {}, v.ids, v.origins);
  };
  const SemanticGrid flat = grid_of(false), pit = grid_of(true);
  for (const double x : {4.375, 4.575, 4.825}) {
    EXPECT_EQ(class_at(flat, x, 2.0), C::floor) << "the flat floor at x " << x;
    EXPECT_NE(class_at(pit, x, 2.0), C::floor) << "the pit at x " << x;
  }
  EXPECT_EQ(class_at(pit, 4.2, 2.0), C::floor) << "the floor before the pit";
}

// Bad free-space options and origins that do not match the views are refused.
TEST(SemanticGridFreeSpace, BadOptionsAndOriginsAreRefused) {
  const std::vector<Eigen::Vector3d> points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<SemanticClass> labels(3, C::floor);
  const std::vector<std::uint32_t> ids{0, 1, 2};
  const std::vector<Eigen::Vector3d> two{{0, 0, 1}, {1, 1, 1}};
  EXPECT_ERROR_MENTIONS(build_semantic_grid(points, labels, {}, {}, ids, two), "origins");
  EXPECT_ERROR_MENTIONS(build_semantic_grid(points, labels, {}, {}, {}, two), "origins");
  SemanticGridParams p;
  p.free_space_slab = 0;
  EXPECT_THROW(p.validate(), Error);
  p = {};
  p.free_space_ray_stride = -1;
  EXPECT_THROW(p.validate(), Error);
  p = {};
  p.free_space_end_margin = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(p.validate(), Error);
  p = {};
  p.seen_through_wall_range = -1;
  EXPECT_THROW(p.validate(), Error);
  p = {};
  p.face_spill_ratio = std::numeric_limits<double>::quiet_NaN();
  EXPECT_ERROR_MENTIONS(p.validate(), "face_spill_ratio");
  p = {};
  p.phantom_pass_ratio = -1;
  EXPECT_ERROR_MENTIONS(p.validate(), "phantom_pass_ratio");
  p = {};
  p.phantom_margin = std::numeric_limits<double>::quiet_NaN();
  EXPECT_ERROR_MENTIONS(p.validate(), "phantom_margin");
  p = {};
  p.furniture_join_gap = 0;
  EXPECT_ERROR_MENTIONS(p.validate(), "furniture_join_gap");
}

}  // namespace
}  // namespace kartograf::semantic
