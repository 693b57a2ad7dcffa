// The synthetic world: determinism, the building's invariants (sizes, connectivity, clear
// doorways and route), the planes' consistency, and the rounded route.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <queue>
#include <set>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::synth {
namespace {

constexpr double kEps = 1e-9;

// Everything that defines the world's geometry and appearance, flattened for comparison.
std::vector<double> fingerprint(const World& w) {
  std::vector<double> v = {w.height, w.wall_thickness, static_cast<double>(w.planes.size())};
  for (const Room& r : w.rooms)
    v.insert(v.end(), {r.rect.min.x(), r.rect.min.y(), r.rect.max.x(), r.rect.max.y()});
  for (const Solid& s : w.solids) {
    for (int a = 0; a < 3; ++a) v.insert(v.end(), {s.box.min[a], s.box.max[a]});
  }
  for (const Plane& p : w.planes) {
    v.insert(v.end(),
             {p.normal.x(), p.normal.y(), p.normal.z(), p.offset, static_cast<double>(p.semantic)});
  }
  for (const Material& m : w.materials) {
    v.insert(v.end(),
             {m.color_a.x(), m.color_b.y(), m.period, static_cast<double>(m.seed % 1000003)});
  }
  return v;
}

TEST(SynthWorld, DeterministicFromSeed) {
  EXPECT_EQ(fingerprint(make_building(7)), fingerprint(make_building(7)));
  EXPECT_NE(fingerprint(make_building(7)), fingerprint(make_building(8)));
}

bool in_range(double value, double lo, double hi) {
  return value >= lo - kEps && value <= hi + kEps;
}

// Room sizes in range, the corridor's width, and no two rooms closer than a wall.
void expect_rooms_in_range(const World& w) {
  const BuildingParams& o = w.options;
  for (const Room& r : w.rooms) {
    EXPECT_EQ(r.id, &r - w.rooms.data() + 1);
    if (r.kind == RoomKind::corridor) {
      EXPECT_TRUE(in_range(r.rect.size().y(), o.min_corridor_width, o.max_corridor_width));
    } else {
      EXPECT_TRUE(in_range(r.rect.size().x(), 3.0, 6.0)) << r.name;
      EXPECT_TRUE(in_range(r.rect.size().y(), 3.0, 6.0)) << r.name;
    }
    for (const Room& other : w.rooms) {
      if (&other != &r) {
        EXPECT_FALSE(r.rect.overlaps(other.rect.expanded(w.wall_thickness - 1e-6)));
      }
    }
  }
}

// Doorways: sizes in range, spanning exactly one wall between the two rooms they join; the
// building connected, and every room with a doorway to the corridor.
void expect_doorways_connect_rooms(const World& w) {
  std::vector<std::set<Label>> neighbours(w.rooms.size() + 1);
  for (const Doorway& d : w.doorways) {
    EXPECT_TRUE(in_range(d.width, 0.8, 1.0));
    EXPECT_TRUE(in_range(d.height, 2.0, 2.1));
    EXPECT_NEAR(d.opening.size()[1 - d.passage_axis], d.width, kEps);
    EXPECT_NEAR(d.opening.size()[d.passage_axis], w.wall_thickness, kEps);
    for (Label id : d.rooms) {
      const Rect2& r = w.room(id).rect;
      const int a = d.passage_axis;
      EXPECT_TRUE(std::fabs(r.min[a] - d.opening.max[a]) < kEps ||
                  std::fabs(r.max[a] - d.opening.min[a]) < kEps);
      EXPECT_GE(d.opening.min[1 - a], r.min[1 - a] + 0.3);  // not in a corner
      EXPECT_LE(d.opening.max[1 - a], r.max[1 - a] - 0.3);
    }
    neighbours[d.rooms[0]].insert(d.rooms[1]);
    neighbours[d.rooms[1]].insert(d.rooms[0]);
  }
  const Label corridor = w.rooms.back().id;
  std::set<Label> seen = {corridor};
  std::queue<Label> queue;
  queue.push(corridor);
  while (!queue.empty()) {
    for (Label n : neighbours[queue.front()]) {
      if (seen.insert(n).second) queue.push(n);
    }
    queue.pop();
  }
  EXPECT_EQ(seen.size(), w.rooms.size());
  for (const Room& r : w.rooms) {
    if (r.kind == RoomKind::room) {
      EXPECT_TRUE(neighbours[r.id].count(corridor)) << r.name;
    }
  }
}

// Furniture: inside its room, clear of doorways and of the robot's route.
void expect_furniture_clear(const World& w) {
  const std::vector<Eigen::Vector2d> route = route_path(w).sample(0.02);
  EXPECT_GE(w.furniture.size(), 4u);
  for (const Furniture& f : w.furniture) {
    const Rect2& room = w.room(f.room).rect;
    EXPECT_TRUE(room.contains(f.footprint.min) && room.contains(f.footprint.max));
    for (const Doorway& d : w.doorways) {
      Rect2 zone = d.opening;
      zone.min[d.passage_axis] -= 0.6;
      zone.max[d.passage_axis] += 0.6;
      EXPECT_FALSE(zone.overlaps(f.footprint))
          << "furniture " << f.id << " blocks doorway " << d.id;
    }
    for (const Eigen::Vector2d& p : route) ASSERT_GE(f.footprint.distance(p), 0.45 - kEps);
  }
}

// Solids are proper boxes, and no wall stands in a doorway below its lintel.
void expect_solids_proper(const World& w) {
  for (const Solid& solid : w.solids) {
    EXPECT_GT((solid.box.max - solid.box.min).minCoeff(), 0.009);
    if (solid.kind != SolidKind::wall) continue;
    for (const Doorway& d : w.doorways) {
      if (solid.box.min.z() < d.height) {
        EXPECT_FALSE(solid.box.footprint().overlaps(d.opening)) << d.id;
      }
    }
  }
}

// At least one dark surface (dropped returns).
bool has_dark_surface(const World& w) {
  bool dark = false;
  for (const Plane& p : w.planes) {
    if (p.material >= 0 && luminance(w.materials[p.material].color_a) < 0.08) dark = true;
  }
  return dark;
}

TEST(SynthWorld, BuildingInvariantsAcrossSeeds) {
  for (std::uint64_t seed = 1; seed <= 25; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const World w = make_building(seed);
    ASSERT_EQ(w.rooms.size(), 5u);  // 4 rooms and the corridor
    EXPECT_TRUE(in_range(w.height, 2.5, 3.0));
    EXPECT_TRUE(in_range(w.wall_thickness, 0.1, 0.2));
    expect_rooms_in_range(w);
    expect_doorways_connect_rooms(w);
    ASSERT_NO_FATAL_FAILURE(expect_furniture_clear(w));
    expect_solids_proper(w);
    EXPECT_TRUE(has_dark_surface(w));
  }
}

TEST(SynthWorld, PlanesAreConsistent) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const World w = make_building(seed);
    ASSERT_LT(w.planes.size(), 65535u);
    for (const Plane& p : w.planes) {
      EXPECT_EQ(p.id, &p - w.planes.data() + 1);
      EXPECT_NEAR(p.normal.norm(), 1.0, kEps);
      EXPECT_NEAR(p.normal.cwiseAbs().maxCoeff(), 1.0, kEps);  // axis-aligned
      EXPECT_NE(p.semantic, SemanticClass::unknown);
      EXPECT_GT(p.area(), 0.0) << p.name;
      for (const auto& polygon : p.polygons) {
        ASSERT_EQ(polygon.size(), 4u);
        for (const Eigen::Vector3d& v : polygon)
          EXPECT_NEAR(p.signed_distance(v), 0.0, kEps) << p.name;
        // Counter-clockwise seen from the normal side.
        const Eigen::Vector3d n = (polygon[1] - polygon[0]).cross(polygon[2] - polygon[1]);
        EXPECT_GT(n.dot(p.normal), 0.0) << p.name;
      }
    }
    EXPECT_EQ(w.plane(w.floor_plane).semantic, SemanticClass::floor);
    EXPECT_EQ(w.plane(w.ceiling_plane).semantic, SemanticClass::ceiling);
    // The floor covers the rooms and the doorways exactly.
    double floor_area = 0;
    for (const Room& r : w.rooms) floor_area += r.rect.area();
    for (const Doorway& d : w.doorways) floor_area += d.opening.area();
    EXPECT_NEAR(w.plane(w.floor_plane).area(), floor_area, 1e-9);
    // A wall's area is the wall minus its doorways.
    for (const Room& r : w.rooms) {
      for (int f = 0; f < 4; ++f) {
        const int axis = f / 2, along = 1 - axis;
        const double level = (f % 2) ? r.rect.min[axis] : r.rect.max[axis];
        double expected = r.rect.size()[along] * w.height;
        for (const Doorway& d : w.doorways) {
          const bool in_wall =
              d.passage_axis == axis && (std::fabs(d.opening.min[axis] - level) < kEps ||
                                         std::fabs(d.opening.max[axis] - level) < kEps);
          if (in_wall && d.opening.min[along] < r.rect.max[along] &&
              d.opening.max[along] > r.rect.min[along]) {
            expected -= d.width * d.height;
          }
        }
        EXPECT_NEAR(w.plane(r.wall_planes[f]).area(), expected, 1e-9) << r.name << " wall " << f;
      }
    }
    // Door leaves: class door, 4 cm thick, standing against the wall beside their doorway.
    for (const DoorLeaf& leaf : w.door_leaves) {
      const Box3& b = w.solids[leaf.solid].box;
      const Doorway& d = w.doorways[leaf.doorway - 1];
      const int a = d.passage_axis, along = 1 - a;
      EXPECT_NEAR(b.max[a] - b.min[a], 0.04, kEps);
      EXPECT_NEAR(b.max[along] - b.min[along], d.width, kEps);
      EXPECT_TRUE(std::fabs(b.max[along] - d.opening.min[along]) < kEps ||
                  std::fabs(b.min[along] - d.opening.max[along]) < kEps);
      const double gap =
          std::min(std::fabs(b.min[a] - d.opening.max[a]), std::fabs(b.max[a] - d.opening.min[a]));
      EXPECT_LE(gap, 0.02);
      for (Label id : w.solids[leaf.solid].face_planes) {
        if (id) {
          EXPECT_EQ(w.plane(id).semantic, SemanticClass::door);
        }
      }
    }
  }
}

TEST(SynthWorld, WallPlaneLookup) {
  const World w = make_building(3);
  for (const Room& r : w.rooms) {
    // 0.1 m from a corner, where no doorway is.
    const Eigen::Vector3d east(r.rect.max.x(), r.rect.min.y() + 0.1, 0.5);
    EXPECT_EQ(w.wall_plane_at(east, Face::neg_x), r.wall_planes[0]) << r.name;
    const Eigen::Vector3d north(r.rect.min.x() + 0.1, r.rect.max.y(), 2.4);
    EXPECT_EQ(w.wall_plane_at(north, Face::neg_y), r.wall_planes[2]) << r.name;
  }
  for (const Doorway& d : w.doorways) {
    const int a = d.passage_axis, along = 1 - a;
    Eigen::Vector3d jamb(0, 0, 1.0);
    jamb[a] = d.opening.center()[a];
    jamb[along] = d.opening.min[along];
    EXPECT_EQ(w.wall_plane_at(jamb, make_face(along, true)), d.jamb_planes[0]);
    jamb[along] = d.opening.max[along];
    EXPECT_EQ(w.wall_plane_at(jamb, make_face(along, false)), d.jamb_planes[1]);
    const Eigen::Vector3d soffit(d.opening.center().x(), d.opening.center().y(), d.height);
    EXPECT_EQ(w.wall_plane_at(soffit, Face::neg_z), d.soffit_plane);
  }
}

TEST(SynthWorld, RejectsBadOptions) {
  BuildingParams o;
  o.room_count = 0;
  EXPECT_THROW(make_building(1, o), Error);
  o = {};
  o.min_door_width = 1.2;
  EXPECT_THROW(make_building(1, o), Error);
  o = {};
  o.max_door_height = 2.9;  // no lintel under a 2.5 m ceiling
  EXPECT_THROW(make_building(1, o), Error);
}

TEST(SynthWorld, OtherRoomCountsStillConnectAndLoop) {
  for (int rooms : {1, 2, 3, 5, 6}) {
    BuildingParams o;
    o.room_count = rooms;
    const World w = make_building(11, o);
    EXPECT_EQ(w.rooms.size(), static_cast<std::size_t>(rooms + 1));
    const RoutePath path = route_path(w);
    std::set<Label> visited;
    for (const Eigen::Vector2d& p : path.sample(0.05)) visited.insert(w.room_at(p));
    visited.erase(0);
    EXPECT_EQ(visited.size(), w.rooms.size()) << rooms << " rooms";
  }
}

TEST(SynthRoute, SquareLoopWithRoundedCorners) {
  // A 4 m square starting mid-side; max radius 1 m: each 90 degree corner becomes a quarter circle.
  const std::vector<RouteVertex> square = {
      {{2, 0}, 0}, {{4, 0}, 0}, {{4, 4}, 0}, {{0, 4}, 0}, {{0, 0}, 0}};
  const RoutePath path(square, 1.0);
  const double expected = 16.0 - 4 * 2.0 + 4 * (std::numbers::pi / 2);
  EXPECT_NEAR(path.length(), expected, 1e-12);
  EXPECT_NEAR(path.heading(path.length()) - path.heading(0), 2 * std::numbers::pi, 1e-12);
  // Continuous position and heading (C1): no jumps between fine samples.
  const double ds = 1e-3;
  for (double s = ds; s < path.length(); s += ds) {
    EXPECT_LT((path.position(s) - path.position(s - ds)).norm(), ds * 1.0001);
    EXPECT_LT(std::fabs(path.heading(s) - path.heading(s - ds)), ds * 1.0001);  // curvature <= 1
  }
  EXPECT_LT((path.position(path.length()) - Eigen::Vector2d(2, 0)).norm(), 1e-12);
  // The arc through the corner at (4, 0) passes at distance r (sqrt 2 - 1) from it.
  double closest = 1e9;
  for (const Eigen::Vector2d& p : path.sample(1e-3))
    closest = std::min(closest, (p - Eigen::Vector2d(4, 0)).norm());
  EXPECT_NEAR(closest, std::sqrt(2.0) - 1.0, 1e-6);
}

TEST(SynthRoute, StraightMarginsAndBadRoutes) {
  // A doorway-like vertex on the first side keeps 1.5 m straight on both sides: the corners get
  // at most 0.5 m tangents there.
  const std::vector<RouteVertex> route = {{{1, 0}, 0}, {{2, 0}, 1.5}, {{4, 0}, 0},
                                          {{4, 4}, 0}, {{0, 4}, 0},   {{0, 0}, 0}};
  const RoutePath path(route, 2.0);
  for (double s = 0; s < 3.0; s += 0.01) {
    const Eigen::Vector2d p = path.position(s);
    if (p.x() >= 0.5 && p.x() <= 3.5) {
      EXPECT_NEAR(p.y(), 0.0, 1e-12);
    }
  }
  EXPECT_THROW(RoutePath({{{0, 0}, 0}, {{1, 0}, 0}}, 1.0), Error);  // too few
  EXPECT_THROW(RoutePath({{{0, 0}, 0}, {{1, 0}, 0}, {{1, 1}, 0}}, 1.0),
               Error);  // starts at a corner
  EXPECT_THROW(RoutePath({{{1, 0}, 0}, {{1, 0}, 0}, {{2, 1}, 0}, {{0, 1}, 0}}, 1.0),
               Error);  // repeated
}

}  // namespace
}  // namespace kartograf::synth
