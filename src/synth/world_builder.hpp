#pragma once
// Internal to make_building: the steps after the layout (door leaves, furniture) and the helpers
// they share with it (materials, planes of boxes).
#include <string>
#include <vector>

#include "kartograf/core/random.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::synth::detail {

// Material palettes; each call adds a new material to the world and returns its index.
int add_wall_material(World& world, Rng& rng, const std::string& name);
int add_floor_material(World& world, Rng& rng, const std::string& name, bool corridor);
int add_ceiling_material(World& world, Rng& rng);
int add_furniture_material(World& world, Rng& rng, const std::string& name, bool dark);
int add_door_material(World& world, Rng& rng, const std::string& name, bool dark);

// A counter-clockwise (seen from the normal side) rectangle on an axis-aligned plane: the face
// whose outward normal is `face`, at coordinate `level` on its axis, spanning [lo, hi] on the
// two other axes (in x, y, z order).
std::vector<Eigen::Vector3d> face_rectangle(Face face, double level, const Eigen::Vector2d& lo,
                                            const Eigen::Vector2d& hi);

// Appends a plane and returns its id.
Label add_plane(World& world, SemanticClass semantic, Face face, double level,
                std::vector<std::vector<Eigen::Vector3d>> polygons, Label room, int material,
                std::string name);

// Adds `box` as an object solid with a plane for every face not listed in `hidden`.
int add_object_solid(World& world, const Box3& box, const std::array<bool, kFaceCount>& hidden,
                     SemanticClass semantic, Label room, int material, const std::string& name);

// Open door leaves beside some doorways (before furniture, which then keeps clear of them).
void add_door_leaves(World& world, Rng& rng);

// Furniture in every room except the corridor, clear of doorways, door leaves and the route.
void furnish(World& world, Rng& rng);

}  // namespace kartograf::synth::detail
