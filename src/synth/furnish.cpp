// Door leaves and furniture: placed by rejection sampling, clear of doorways, of each other and
// of the robot's route (so that the tour never has to avoid anything).
#include <algorithm>
#include <array>
#include <string>

#include "world_builder.hpp"

namespace kartograf::synth::detail {

namespace {

constexpr double kRouteClearance = 0.45;  // furniture to route
constexpr double kDoorZoneDepth = 1.0;    // kept free in front of every doorway
constexpr double kItemGap = 0.08;         // between pieces of furniture
constexpr double kWallGap = 0.02;         // between furniture and the wall behind it
constexpr int kAttempts = 40;

// A box in an item's own frame: u along its width, d its depth from the back, z up. Hidden
// faces (touching another part or the floor) get no plane: [u-, u+, d-, d+, z-, z+].
struct LocalBox {
  double u0, u1, d0, d1, z0, z1;
  std::array<bool, kFaceCount> hidden{};
  std::string part;
};

// Where an item stands: u runs along world axis `along_axis` from u_origin, d along the other
// horizontal axis from d_origin in direction depth_sign.
struct Placement {
  int along_axis = 0;
  double depth_sign = 1;
  double u_origin = 0;
  double d_origin = 0;

  int depth_axis() const { return 1 - along_axis; }

  Box3 to_world(const LocalBox& b) const {
    Box3 box;
    const int a = along_axis, d = depth_axis();
    box.min[a] = u_origin + b.u0;
    box.max[a] = u_origin + b.u1;
    box.min[d] = depth_sign > 0 ? d_origin + b.d0 : d_origin - b.d1;
    box.max[d] = depth_sign > 0 ? d_origin + b.d1 : d_origin - b.d0;
    box.min.z() = b.z0;
    box.max.z() = b.z1;
    return box;
  }

  std::array<bool, kFaceCount> to_world(const std::array<bool, kFaceCount>& hidden) const {
    std::array<bool, kFaceCount> out{};
    const int a = along_axis, d = depth_axis();
    out[static_cast<int>(make_face(a, false))] = hidden[0];
    out[static_cast<int>(make_face(a, true))] = hidden[1];
    out[static_cast<int>(make_face(d, depth_sign < 0))] = hidden[2];
    out[static_cast<int>(make_face(d, depth_sign > 0))] = hidden[3];
    out[4] = hidden[4];
    out[5] = hidden[5];
    return out;
  }
};

constexpr std::array<bool, kFaceCount> kOnFloor = {false, false, false, false, true, false};

struct Design {
  FurnitureKind kind = FurnitureKind::cabinet;
  double width = 0, depth = 0, height = 0;
  bool against_wall = true;
  std::vector<LocalBox> parts;
};

struct Range {
  double low, high;
};

// A design of `kind` with its width, depth and height drawn from the ranges, in that order (the
// order of the draws fixes the world a seed makes).
Design sized(FurnitureKind kind, Rng& rng, Range width, Range depth, Range height) {
  Design d;
  d.kind = kind;
  d.width = rng.uniform(width.low, width.high);
  d.depth = rng.uniform(depth.low, depth.high);
  d.height = rng.uniform(height.low, height.high);
  return d;
}

Design cabinet(Rng& rng) {
  Design d = sized(FurnitureKind::cabinet, rng, {0.5, 1.2}, {0.4, 0.6}, {0.7, 1.3});
  d.parts.push_back({0, d.width, 0, d.depth, 0, d.height, kOnFloor, "body"});
  return d;
}

Design crate(Rng& rng) {
  Design d = sized(FurnitureKind::crate, rng, {0.3, 0.6}, {0.3, 0.6}, {0.25, 0.5});
  const double lower = d.height;
  d.parts.push_back({0, d.width, 0, d.depth, 0, lower, kOnFloor, "lower"});
  if (rng.bernoulli(0.5)) {  // a smaller crate on top, set back from the front edge
    const double w = d.width * rng.uniform(0.5, 0.9), dd = d.depth * rng.uniform(0.5, 0.9);
    const double u0 = rng.uniform(0.0, d.width - w);
    d.height = lower + rng.uniform(0.2, 0.4);
    d.parts.push_back({u0, u0 + w, 0, dd, lower, d.height, kOnFloor, "upper"});
  }
  d.against_wall = rng.bernoulli(0.6);
  return d;
}

Design table(Rng& rng) {
  Design d = sized(FurnitureKind::table, rng, {0.8, 1.6}, {0.6, 1.0}, {0.72, 0.76});
  const double top = rng.uniform(0.03, 0.04), leg = 0.05, inset = 0.04;
  d.parts.push_back({0, d.width, 0, d.depth, d.height - top, d.height, {}, "top"});
  const std::array<bool, kFaceCount> leg_hidden = {false, false, false, false, true, true};
  int n = 0;
  for (double u : {inset, d.width - inset - leg}) {
    for (double v : {inset, d.depth - inset - leg}) {
      d.parts.push_back(
          {u, u + leg, v, v + leg, 0, d.height - top, leg_hidden, "leg " + std::to_string(++n)});
    }
  }
  d.against_wall = rng.bernoulli(0.4);
  return d;
}

Design shelf(Rng& rng) {
  Design d = sized(FurnitureKind::shelf, rng, {0.6, 1.2}, {0.28, 0.4}, {1.5, 2.0});
  const double p = 0.02, back = 0.01;
  d.parts.push_back({0, p, 0, d.depth, 0, d.height, kOnFloor, "side 1"});
  d.parts.push_back({d.width - p, d.width, 0, d.depth, 0, d.height, kOnFloor, "side 2"});
  d.parts.push_back(
      {p, d.width - p, 0, back, 0, d.height, {true, true, false, false, true, false}, "back"});
  const int boards = rng.uniform_int(4, 6);
  const std::array<bool, kFaceCount> board_hidden = {true, true, true, false, false, false};
  for (int i = 0; i < boards; ++i) {
    const double z = 0.05 + (d.height - p - 0.05) * i / (boards - 1);
    d.parts.push_back(
        {p, d.width - p, back, d.depth, z, z + p, board_hidden, "board " + std::to_string(i + 1)});
  }
  return d;
}

Design random_design(Rng& rng) {
  const double pick = rng.uniform();
  if (pick < 0.3) return cabinet(rng);
  if (pick < 0.6) return table(rng);
  if (pick < 0.85) return shelf(rng);
  return crate(rng);
}

class Furnisher {
 public:
  Furnisher(World& world, Rng& rng) : w_(world), rng_(rng) {
    route_ = route_path(world).sample(0.05);
    obstacles_ = world.obstacle_footprints();
  }

  double route_distance(const Rect2& r) const {
    double best = 1e9;
    for (const Eigen::Vector2d& p : route_) best = std::min(best, r.distance(p));
    return best;
  }

  // Free in front of every doorway of `room` (excluding `except`) and clear of obstacles.
  bool clear_of_doorways(const Rect2& r, Label room, int except = -1) const {
    for (const Doorway& door : w_.doorways) {
      if (door.id == except || (door.rooms[0] != room && door.rooms[1] != room)) continue;
      Rect2 zone = door.opening;
      zone.min[door.passage_axis] -= kDoorZoneDepth;
      zone.max[door.passage_axis] += kDoorZoneDepth;
      zone.min[1 - door.passage_axis] -= 0.1;
      zone.max[1 - door.passage_axis] += 0.1;
      if (zone.overlaps(r)) return false;
    }
    return true;
  }

  bool clear_of_obstacles(const Rect2& r, double gap) const {
    const Rect2 grown = r.expanded(gap);
    return std::none_of(obstacles_.begin(), obstacles_.end(),
                        [&](const Rect2& o) { return o.overlaps(grown); });
  }

  void add_door_leaves() {
    for (const Doorway& door : w_.doorways) {
      if (!rng_.bernoulli(w_.options.door_leaf_probability)) continue;
      const int first_side = rng_.uniform_int(0, 1);
      const bool first_low = rng_.bernoulli(0.5);
      const bool dark = rng_.bernoulli(0.25);
      for (int attempt = 0; attempt < 4; ++attempt) {
        const Room& room = w_.room(door.rooms[(first_side + attempt / 2) % 2]);
        const bool hinge_low = first_low != (attempt % 2 == 1);
        if (try_leaf(door, room, hinge_low, dark)) break;
      }
    }
  }

  bool try_leaf(const Doorway& door, const Room& room, bool hinge_low, bool dark) {
    constexpr double kThickness = 0.04, kGap = 0.01;
    const int axis = door.passage_axis, along = 1 - axis;
    const bool room_above = room.rect.min[axis] >= door.opening.max[axis] - 1e-9;
    const double level = room_above ? room.rect.min[axis] : room.rect.max[axis];
    const double into = room_above ? 1.0 : -1.0;
    Box3 box;
    box.min[along] = hinge_low ? door.opening.min[along] - door.width : door.opening.max[along];
    box.max[along] = box.min[along] + door.width;
    box.min[axis] = into > 0 ? level + kGap : level - kGap - kThickness;
    box.max[axis] = box.min[axis] + kThickness;
    box.min.z() = 0;
    box.max.z() = door.height - 0.02;
    const Rect2 foot = box.footprint();
    if (box.min[along] < room.rect.min[along] + 0.05 ||
        box.max[along] > room.rect.max[along] - 0.05 ||
        !clear_of_doorways(foot, room.id, door.id) || !clear_of_obstacles(foot, 0.05) ||
        route_distance(foot) < 0.4 - 1e-9) {
      return false;
    }
    const std::string name = "door leaf " + std::to_string(w_.door_leaves.size() + 1);
    DoorLeaf leaf;
    leaf.doorway = door.id;
    leaf.room = room.id;
    leaf.material = add_door_material(w_, rng_, name, dark);
    leaf.solid =
        add_object_solid(w_, box, kOnFloor, SemanticClass::door, room.id, leaf.material, name);
    w_.door_leaves.push_back(leaf);
    obstacles_.push_back(foot);
    return true;
  }

  void furnish_room(const Room& room) {
    const int count = rng_.uniform_int(w_.options.min_furniture, w_.options.max_furniture);
    for (int item = 0; item < count; ++item) {
      const Design design = random_design(rng_);
      for (int attempt = 0; attempt < kAttempts; ++attempt) {
        const Placement placement = place(room, design);
        Rect2 foot{Eigen::Vector2d::Constant(1e9), Eigen::Vector2d::Constant(-1e9)};
        for (const LocalBox& part : design.parts) {
          const Rect2 f = placement.to_world(part).footprint();
          foot.min = foot.min.cwiseMin(f.min);
          foot.max = foot.max.cwiseMax(f.max);
        }
        const Rect2 inner = room.rect.expanded(-0.01);
        if (!inner.contains(foot.min) || !inner.contains(foot.max) ||
            !clear_of_doorways(foot, room.id) || !clear_of_obstacles(foot, kItemGap) ||
            route_distance(foot) < kRouteClearance) {
          continue;
        }
        add_item(room, design, placement, foot);
        break;
      }
    }
  }

  Placement place(const Room& room, const Design& design) {
    Placement p;
    if (design.against_wall) {
      const Face face = static_cast<Face>(rng_.uniform_int(0, 3));  // normal into the room
      const int axis = face_axis(face);
      p.along_axis = 1 - axis;
      p.depth_sign = face_sign(face);
      p.d_origin =
          (p.depth_sign > 0 ? room.rect.min[axis] : room.rect.max[axis]) + p.depth_sign * kWallGap;
      const double lo = room.rect.min[p.along_axis] + 0.02;
      const double hi = room.rect.max[p.along_axis] - 0.02 - design.width;
      p.u_origin = rng_.uniform(lo, std::max(lo, hi));
    } else {
      p.along_axis = rng_.uniform_int(0, 1);
      p.depth_sign = 1;
      const int d = p.depth_axis();
      const double margin = 0.5;
      p.u_origin = rng_.uniform(room.rect.min[p.along_axis] + margin,
                                std::max(room.rect.min[p.along_axis] + margin,
                                         room.rect.max[p.along_axis] - margin - design.width));
      p.d_origin = rng_.uniform(
          room.rect.min[d] + margin,
          std::max(room.rect.min[d] + margin, room.rect.max[d] - margin - design.depth));
    }
    return p;
  }

  void add_item(const Room& room, const Design& design, const Placement& placement,
                const Rect2& foot) {
    Furniture item;
    item.id = static_cast<int>(w_.furniture.size() + 1);
    item.kind = design.kind;
    item.room = room.id;
    item.footprint = foot;
    item.height = design.height;
    const std::string name =
        "furniture " + std::to_string(item.id) + " (" + to_string(design.kind) + ")";
    item.material = add_furniture_material(w_, rng_, name, rng_.bernoulli(0.15));
    for (const LocalBox& part : design.parts) {
      item.solids.push_back(add_object_solid(
          w_, placement.to_world(part), placement.to_world(part.hidden), SemanticClass::furniture,
          room.id, item.material, name + " " + part.part));
    }
    w_.furniture.push_back(item);
    obstacles_.push_back(foot);
  }

  // At least one dark surface: when chance gave none, the first item becomes black.
  void ensure_dark_surface() {
    auto is_dark = [&](int material) { return luminance(w_.materials[material].color_a) < 0.1; };
    for (const Furniture& item : w_.furniture) {
      if (is_dark(item.material)) return;
    }
    for (const DoorLeaf& leaf : w_.door_leaves) {
      if (is_dark(leaf.material)) return;
    }
    if (w_.furniture.empty()) return;
    Furniture& item = w_.furniture.front();
    item.material = add_furniture_material(w_, rng_, "furniture 1 (dark)", true);
    for (int solid : item.solids) {
      w_.solids[solid].material = item.material;
      for (Label id : w_.solids[solid].face_planes) {
        if (id) w_.planes[id - 1].material = item.material;
      }
    }
  }

 private:
  World& w_;
  Rng& rng_;
  std::vector<Eigen::Vector2d> route_;
  std::vector<Rect2> obstacles_;
};

}  // namespace

void add_door_leaves(World& world, Rng& rng) {
  Furnisher(world, rng).add_door_leaves();
}

void furnish(World& world, Rng& rng) {
  Furnisher furnisher(world, rng);
  for (const Room& room : world.rooms) {
    if (room.kind == RoomKind::corridor) continue;
    Rng room_rng = rng.fork(room.id);
    Furnisher(world, room_rng).furnish_room(room);
  }
  furnisher.ensure_dark_surface();
}

}  // namespace kartograf::synth::detail
