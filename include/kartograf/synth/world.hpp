#pragma once
// The synthetic indoor world: a building of rectangular rooms along a corridor, with doorways,
// door leaves, furniture and textured materials, generated deterministically from a seed, with
// exact ground truth: every visible planar face is a plane with an id, a semantic class, its
// equation and its polygon; every room has an id and a rectangle.
//
// Frame: metres, z up, floor at z = 0, ceiling at z = height. The layout (rooms, walls, doorways)
// lies on a grid of BuildingParams::grid_step (5 cm), so that a 5 cm floor plan is exact.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/synth/material.hpp"
#include "kartograf/synth/route.hpp"
#include "kartograf/synth/shapes.hpp"

namespace kartograf::synth {

struct BuildingParams {
  int room_count = 4;  // rooms besides the corridor, 1..10: half north of the corridor, half south
  double min_room_side = 3.0, max_room_side = 6.0;
  double min_ceiling = 2.5, max_ceiling = 3.0;  // one height for the whole building
  double min_corridor_width = 1.5, max_corridor_width = 2.0;
  double min_door_width = 0.8, max_door_width = 1.0;
  double min_door_height = 2.0, max_door_height = 2.1;
  double min_wall_thickness = 0.1, max_wall_thickness = 0.2;
  int min_furniture = 2, max_furniture = 4;  // items per room (fewer when a room has no space)
  double door_leaf_probability = 0.6;        // an open door leaf beside a doorway
  double grid_step = 0.05;                   // layout coordinates are multiples of this
  // The layout is redrawn (up to 100 times) until a robot tour of this many frames fits the
  // default TourParams' per-frame limits (12 cm, 4 degrees); 0: no such constraint.
  int tour_frames = 300;

  // Throws Error naming the first inconsistent field.
  void validate() const;
};

enum class RoomKind : std::uint8_t { room, corridor };

struct Room {
  Label id = 0;
  std::string name;
  RoomKind kind = RoomKind::room;
  Rect2 rect;  // interior, between the wall faces
  // The room's four wall planes, indexed by the face normal that points into the room:
  // [neg_x] the wall at rect.max.x, [pos_x] at rect.min.x, [neg_y] at rect.max.y, [pos_y] at
  // rect.min.y.
  std::array<Label, 4> wall_planes{};
  int wall_material = 0;
  int floor_material = 0;
};

// An opening through a wall between two rooms, from the floor to `height`, with a lintel above.
struct Doorway {
  int id = 0;                    // 1-based
  std::array<Label, 2> rooms{};  // the rooms on either side
  Rect2 opening;                 // footprint: width along the wall x wall thickness
  int passage_axis = 1;          // the axis one walks along through it (the wall's normal axis)
  double width = 0;
  double height = 0;
  // Side faces of the opening: [0] at the low end along the wall (normal +), [1] at the high end.
  std::array<Label, 2> jamb_planes{};
  Label soffit_plane = 0;  // underside of the lintel
};

enum class SolidKind : std::uint8_t {
  wall,    // wall or lintel piece: which plane a face belongs to depends on the room it faces
  object,  // furniture or door leaf: one plane per face (face_planes)
};

struct Solid {
  Box3 box;
  SolidKind kind = SolidKind::wall;
  std::array<Label, kFaceCount> face_planes{};  // objects only; 0 = a hidden contact face
  int material = -1;                            // objects only
};

enum class FurnitureKind : std::uint8_t { cabinet, table, shelf, crate };
std::string to_string(FurnitureKind kind);

struct Furniture {
  int id = 0;  // 1-based
  FurnitureKind kind = FurnitureKind::cabinet;
  Label room = 0;
  Rect2 footprint;
  double height = 0;
  int material = 0;
  std::vector<int> solids;  // indices into World::solids
};

// A door leaf standing open, flat against the wall beside its doorway.
struct DoorLeaf {
  int doorway = 0;  // Doorway::id
  Label room = 0;   // the room it stands in
  int material = 0;
  int solid = 0;  // index into World::solids
};

struct Plane {
  Label id = 0;
  SemanticClass semantic = SemanticClass::unknown;
  // Unit normal pointing out of the solid (towards the viewer) and offset: n . x + offset = 0.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;
  // The plane's surface: disjoint convex polygons (rectangles here), vertices counter-clockwise
  // seen from the normal side. Floor and ceiling cover every room and doorway (also under
  // furniture); a wall plane has the doorways cut out.
  std::vector<std::vector<Eigen::Vector3d>> polygons;
  Label room = 0;     // the room it bounds or stands in (0 for floor and ceiling)
  int material = -1;  // -1: per room (the floor)
  std::string name;   // e.g. "room 2 north wall", "furniture 3 table top +z"

  double signed_distance(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  double area() const;
};

struct World {
  std::uint64_t seed = 0;
  BuildingParams options;
  double height = 0;  // ceiling height
  double wall_thickness = 0;
  Rect2 bounds;             // footprint of the building, outer walls included
  std::vector<Room> rooms;  // rooms[i].id == i + 1; the corridor is the last
  std::vector<Doorway> doorways;
  std::vector<Solid> solids;
  std::vector<Furniture> furniture;
  std::vector<DoorLeaf> door_leaves;
  std::vector<Plane> planes;  // planes[i].id == i + 1
  std::vector<Material> materials;
  Label floor_plane = 0;
  Label ceiling_plane = 0;
  int ceiling_material = 0;
  std::vector<RouteVertex> route;  // closed tour through every room (see RoutePath)

  const Plane& plane(Label id) const;
  const Room& room(Label id) const;
  // The room whose interior contains p, or 0.
  Label room_at(const Eigen::Vector2d& p) const;
  // Index of the doorway whose opening contains p, or -1.
  int doorway_at(const Eigen::Vector2d& p) const;
  // The plane of a wall-solid face at p, with `face` its outward normal: the wall plane of the
  // room in front of it, or a doorway's jamb or soffit; 0 if p faces no open space.
  Label wall_plane_at(const Eigen::Vector3d& p, Face face) const;
  // Material of the floor at p (per room; a doorway takes its first room's).
  int floor_material_at(const Eigen::Vector2d& p) const;
  // The rectangles a robot cannot drive through at floor level inside rooms: furniture
  // footprints and door leaves.
  std::vector<Rect2> obstacle_footprints() const;
};

// Continuous planar surfaces: for every plane id (index = id, entry 0 unused), the smallest id of
// the planes that form one surface with it: coplanar planes whose polygons touch or overlap, such
// as a table leg flush with the edge of the top. Solids model such faces apart, yet they are one
// plane to any sensor; plane-segmentation scores count them as one.
std::vector<Label> continuous_surface_ids(const World& world);

// Metres from p to the nearest surface of the world: the floor, the ceiling and every solid's box
// (hidden contact faces included). Linear in the solids; for scoring reconstructions.
double distance_to_surfaces(const World& world, const Eigen::Vector3d& p);

// The building for `seed`. Throws Error when the options are inconsistent.
World make_building(std::uint64_t seed, const BuildingParams& options = {});

// The route as a rounded path (radius up to 1.5 m), as the tour drives it.
RoutePath route_path(const World& world);

}  // namespace kartograf::synth
