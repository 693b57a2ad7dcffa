// The building layout: rooms in two rows along a corridor, doorways, walls with lintels, the
// structural planes, and the robot's route. Door leaves and furniture: furnish.cpp.
//
// Layout (plan view, x east, y north):
//
//   +------+-----+---------+
//   |  N1  =  N2 =   N3    |     north row: rooms joined to their neighbours by "chain" doorways
//   +--||--+-----+----||---+
//   |        corridor      |     every room has a doorway to the corridor
//   +--||--+--------+--||--+
//   |  S1  =   S2   =  S3  |     south row
//   +------+--------+------+
//
// The route is one loop: across the corridor into N1, east through the chain doorways to the last
// north room, across the corridor into the last south room, west back to S1 and across the
// corridor to the start. It turns 360 degrees in total (no U-turns), which keeps the per-frame
// rotation of a 300-frame tour small.
#include "kartograf/synth/world.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "world_builder.hpp"

namespace kartograf::synth {

namespace {

using Units = std::int64_t;  // layout coordinates in multiples of BuildingParams::grid_step

constexpr double kDoorMargin = 0.35;    // from a doorway's edge to the room's corner
constexpr double kApproach = 0.5;       // the route is straight this far beyond each wall face
constexpr double kMaxTurnRadius = 1.5;  // the route's arcs
constexpr int kLayoutAttempts = 100;

// West-to-east room indices of one row and where the row's route enters and leaves it.
struct Row {
  std::vector<int> rooms;
  bool north = true;
  double west_door_x = 0, east_door_x = 0;  // centres of the corridor doorways the route uses
  double chain_y = 0;                       // centre line of the chain doorways (rows of >= 2)
  double deep_y = 0;                        // where a one-room row turns around
};

class LayoutBuilder {
 public:
  LayoutBuilder(std::uint64_t seed, const BuildingParams& options) : o_(options), rng_(seed) {
    w_.seed = seed;
    w_.options = options;
  }

  World build() {
    // Room sizes decide the route's length; redraw layouts until the default tour fits.
    for (int attempt = 0;; ++attempt) {
      choose_dimensions();
      place_rooms();
      place_doorways();
      build_route();
      if (o_.tour_frames <= 0 || attempt == kLayoutAttempts - 1 ||
          tour_frames_needed(w_, TourParams{}) <= o_.tour_frames) {
        break;
      }
      w_.rooms.clear();
      w_.doorways.clear();
      w_.materials.clear();
      w_.route.clear();
      rows_.clear();
    }
    build_walls();
    add_structural_planes();
    Rng leaves_rng = rng_.fork(1);
    detail::add_door_leaves(w_, leaves_rng);
    Rng furniture_rng = rng_.fork(2);
    detail::furnish(w_, furniture_rng);
    return std::move(w_);
  }

 private:
  // u / 20 rather than u * 0.05 when the step is 1/n: the double nearest the decimal value
  // (3.3, not 3.3000000000000003), which is what world.json then shows.
  double metres(Units u) const {
    const double per_metre = std::round(1.0 / o_.grid_step);
    if (std::fabs(per_metre * o_.grid_step - 1.0) < 1e-12)
      return static_cast<double>(u) / per_metre;
    return static_cast<double>(u) * o_.grid_step;
  }
  Units units_up(double m) const { return static_cast<Units>(std::ceil(m / o_.grid_step - 1e-9)); }
  Units units_down(double m) const {
    return static_cast<Units>(std::floor(m / o_.grid_step + 1e-9));
  }
  // A lattice value in [low, high] metres, uniformly.
  Units pick(double low, double high, const char* what) {
    const Units lo = units_up(low), hi = units_down(high);
    require(lo <= hi, std::string("make_building: no valid ") + what + " in [" +
                          std::to_string(low) + ", " + std::to_string(high) + "] m");
    return lo + static_cast<Units>(rng_.uniform_int(0, static_cast<int>(hi - lo)));
  }
  double round_cm(double m) const { return std::round(m * 100.0) / 100.0; }

  void choose_dimensions() {
    t_ = pick(o_.min_wall_thickness, o_.max_wall_thickness, "wall thickness");
    corridor_ = pick(o_.min_corridor_width, o_.max_corridor_width, "corridor width");
    w_.wall_thickness = metres(t_);
    w_.height = round_cm(rng_.uniform(o_.min_ceiling, o_.max_ceiling));
  }

  Units pick_side(const char* what) { return pick(o_.min_room_side, o_.max_room_side, what); }

  // Widths of the south row, matching the north row's length when both rows have as many rooms
  // (a rectangular building); rejection sampling of the last width keeps it in range.
  std::vector<Units> south_widths(int count, Units north_length) {
    std::vector<Units> widths(count);
    for (int attempt = 0; attempt < 200 && count > 0; ++attempt) {
      Units sum = 0;
      for (int i = 0; i + 1 < count; ++i) sum += widths[i] = pick_side("room width");
      const Units last = north_length - sum - (count - 1) * t_;
      if (last >= units_up(o_.min_room_side) && last <= units_down(o_.max_room_side)) {
        widths.back() = last;
        return widths;
      }
    }
    for (auto& width : widths) width = pick_side("room width");
    return widths;
  }

  void place_rooms() {
    const int north_count = (o_.room_count + 1) / 2;
    const int south_count = o_.room_count / 2;
    std::vector<Units> north_widths(north_count);
    Units north_length = (north_count - 1) * t_;
    for (auto& width : north_widths) north_length += width = pick_side("room width");
    const std::vector<Units> south = south_count == north_count
                                         ? south_widths(south_count, north_length)
                                         : south_widths(south_count, -1);  // -1: never matches
    Units south_length = (south_count - 1) * t_;
    for (Units width : south) south_length += width;
    length_ = std::max(north_length, south_length);

    auto add_row = [&](const std::vector<Units>& widths, bool north) {
      Row row;
      row.north = north;
      Units x = 0;
      for (Units width : widths) {
        const Units depth = pick_side("room depth");
        const Units y0 = north ? corridor_ + t_ : -t_ - depth;
        Room room;
        room.id = static_cast<Label>(w_.rooms.size() + 1);
        room.name = "room " + std::to_string(room.id);
        room.rect = {{metres(x), metres(y0)}, {metres(x + width), metres(y0 + depth)}};
        row.rooms.push_back(static_cast<int>(w_.rooms.size()));
        w_.rooms.push_back(room);
        x += width + t_;
      }
      return row;
    };
    rows_.push_back(add_row(north_widths, true));
    if (south_count > 0) rows_.push_back(add_row(south, false));

    Room corridor;
    corridor.id = static_cast<Label>(w_.rooms.size() + 1);
    corridor.name = "corridor";
    corridor.kind = RoomKind::corridor;
    corridor.rect = {{0.0, 0.0}, {metres(length_), metres(corridor_)}};
    w_.rooms.push_back(corridor);

    for (Room& room : w_.rooms) {
      const bool is_corridor = room.kind == RoomKind::corridor;
      room.wall_material = detail::add_wall_material(w_, rng_, room.name + " walls");
      room.floor_material = detail::add_floor_material(w_, rng_, room.name + " floor", is_corridor);
    }
    w_.ceiling_material = detail::add_ceiling_material(w_, rng_);
  }

  // A doorway through the wall between rooms a and b. `lo` is its low edge along the wall, the
  // wall spans [wall_lo, wall_hi] on the passage axis.
  void add_doorway(Label a, Label b, int passage_axis, Units lo, Units width, Units wall_lo,
                   Units wall_hi) {
    Doorway door;
    door.id = static_cast<int>(w_.doorways.size() + 1);
    door.rooms = {a, b};
    door.passage_axis = passage_axis;
    door.width = metres(width);
    door.height = round_cm(rng_.uniform(o_.min_door_height, o_.max_door_height));
    const int along = 1 - passage_axis;
    door.opening.min[along] = metres(lo);
    door.opening.max[along] = metres(lo + width);
    door.opening.min[passage_axis] = metres(wall_lo);
    door.opening.max[passage_axis] = metres(wall_hi);
    w_.doorways.push_back(door);
  }

  Units door_width() { return pick(o_.min_door_width, o_.max_door_width, "door width"); }

  // Low edge of a doorway of `width` whose centre lies in [centre_lo, centre_hi] metres.
  Units door_lo(double centre_lo, double centre_hi, Units width, const char* what) {
    const double half = 0.5 * metres(width);
    return pick(centre_lo - half, centre_hi - half, what);
  }

  // Corridor-doorway centre ranges of a room: its west part, its east part, anywhere.
  struct Range {
    double lo, hi;
  };
  Range west_part(const Room& r, Units width) const {
    const double span = r.rect.size().x();
    return {r.rect.min.x() + kDoorMargin + 0.5 * metres(width),
            r.rect.min.x() + (span < 3.6 ? 0.4 : 0.45) * span};
  }
  Range east_part(const Room& r, Units width) const {
    const double span = r.rect.size().x();
    return {r.rect.max.x() - (span < 3.6 ? 0.4 : 0.45) * span,
            r.rect.max.x() - kDoorMargin - 0.5 * metres(width)};
  }
  Range anywhere(const Room& r, Units width) const {
    return {r.rect.min.x() + kDoorMargin + 0.5 * metres(width),
            r.rect.max.x() - kDoorMargin - 0.5 * metres(width)};
  }

  void add_corridor_door(const Row& row, int room_index, Units lo, Units width) {
    const Label corridor_id = w_.rooms.back().id;
    if (row.north) {
      add_doorway(w_.rooms[room_index].id, corridor_id, 1, lo, width, corridor_, corridor_ + t_);
    } else {
      add_doorway(w_.rooms[room_index].id, corridor_id, 1, lo, width, -t_, 0);
    }
  }

  // Picks aligned centres for the same doorway slot of both rows (a straight corridor crossing)
  // when their ranges overlap; otherwise independent ones. Returns the low edges.
  std::vector<Units> aligned_doors(const std::vector<Range>& ranges,
                                   const std::vector<Range>& fallback, Units width) {
    double lo = -1e9, hi = 1e9;
    for (const Range& r : ranges) lo = std::max(lo, r.lo), hi = std::min(hi, r.hi);
    if (units_up(lo - 0.5 * metres(width)) <= units_down(hi - 0.5 * metres(width))) {
      const Units common = door_lo(lo, hi, width, "doorway position");
      return std::vector<Units>(ranges.size(), common);
    }
    lo = -1e9, hi = 1e9;
    for (const Range& r : fallback) lo = std::max(lo, r.lo), hi = std::min(hi, r.hi);
    if (units_up(lo - 0.5 * metres(width)) <= units_down(hi - 0.5 * metres(width))) {
      const Units common = door_lo(lo, hi, width, "doorway position");
      return std::vector<Units>(ranges.size(), common);
    }
    std::vector<Units> independent;
    for (const Range& r : ranges)
      independent.push_back(door_lo(r.lo, r.hi, width, "doorway position"));
    return independent;
  }

  void place_doorways() {
    // The corridor doorways the route uses: the west one of each row's first room, the east one
    // of its last room, aligned across the corridor where possible.
    const Units west_width = door_width();
    const Units east_width = door_width();
    std::vector<Range> west_ranges, east_ranges, east_fallback;
    for (const Row& row : rows_) {
      west_ranges.push_back(west_part(w_.rooms[row.rooms.front()], west_width));
      east_ranges.push_back(east_part(w_.rooms[row.rooms.back()], east_width));
      east_fallback.push_back(anywhere(w_.rooms[row.rooms.back()], east_width));
    }
    const std::vector<Units> west = aligned_doors(west_ranges, west_ranges, west_width);
    const std::vector<Units> east = aligned_doors(east_ranges, east_fallback, east_width);

    for (std::size_t r = 0; r < rows_.size(); ++r) {
      Row& row = rows_[r];
      const int k = static_cast<int>(row.rooms.size());
      add_corridor_door(row, row.rooms.front(), west[r], west_width);
      row.west_door_x = metres(west[r]) + 0.5 * metres(west_width);
      for (int i = 1; i + 1 < k; ++i) {  // middle rooms: a corridor doorway off the route
        const Units width = door_width();
        const Range range = anywhere(w_.rooms[row.rooms[i]], width);
        add_corridor_door(row, row.rooms[i], door_lo(range.lo, range.hi, width, "doorway position"),
                          width);
      }
      add_corridor_door(row, row.rooms.back(), east[r], east_width);
      row.east_door_x = metres(east[r]) + 0.5 * metres(east_width);

      // Chain doorways on one line, in the far half of the shallowest room.
      double depth = 1e9;
      for (int index : row.rooms) depth = std::min(depth, w_.rooms[index].rect.size().y());
      const double near_wall = row.north ? metres(corridor_ + t_) : metres(-t_);
      const double into = row.north ? 1.0 : -1.0;
      row.deep_y = near_wall + into * 0.6 * depth;
      if (k < 2) continue;
      const Units width = door_width();
      const double a = near_wall + into * 0.55 * depth;
      const double b = near_wall + into * (depth - kDoorMargin - 0.5 * metres(width));
      const Units lo = door_lo(std::min(a, b), std::max(a, b), width, "chain doorway position");
      row.chain_y = metres(lo) + 0.5 * metres(width);
      for (int i = 0; i + 1 < k; ++i) {
        const Room& west_room = w_.rooms[row.rooms[i]];
        const Units wall_lo = units_down(west_room.rect.max.x() + 1e-6);
        add_doorway(west_room.id, w_.rooms[row.rooms[i + 1]].id, 0, lo, width, wall_lo,
                    wall_lo + t_);
      }
    }
  }

  void build_walls() {
    const double h = w_.height;
    // In lattice units, so that shared walls and doorway cuts meet exactly (3.5 - 0.2 is not the
    // double nearest 3.3: subtracting in metres would leave slivers in doorways).
    auto units = [&](double m) { return static_cast<Units>(std::llround(m / o_.grid_step)); };
    auto box = [&](Units x0, Units y0, Units x1, Units y1) {
      return Box3{{metres(x0), metres(y0), 0.0}, {metres(x1), metres(y1), h}};
    };
    std::vector<Box3> slabs;
    for (const Room& room : w_.rooms) {
      const Units x0 = units(room.rect.min.x()), y0 = units(room.rect.min.y());
      const Units x1 = units(room.rect.max.x()), y1 = units(room.rect.max.y());
      slabs.push_back(box(x0 - t_, y0 - t_, x1 + t_, y0));
      slabs.push_back(box(x0 - t_, y1, x1 + t_, y1 + t_));
      slabs.push_back(box(x0 - t_, y0, x0, y1));
      slabs.push_back(box(x1, y0, x1 + t_, y1));
    }
    for (const Doorway& door : w_.doorways) {
      const Box3 opening{{door.opening.min.x(), door.opening.min.y(), 0.0},
                         {door.opening.max.x(), door.opening.max.y(), door.height}};
      std::vector<Box3> cut;
      for (const Box3& slab : slabs) {
        for (const Box3& part : subtract(slab, opening)) cut.push_back(part);
      }
      slabs = std::move(cut);
    }
    // Shared walls come once from each side: keep one copy (coordinates are exact lattice values).
    auto key = [](const Box3& b) {
      return std::array<double, 6>{b.min.x(), b.min.y(), b.min.z(),
                                   b.max.x(), b.max.y(), b.max.z()};
    };
    std::sort(slabs.begin(), slabs.end(),
              [&](const Box3& p, const Box3& q) { return key(p) < key(q); });
    slabs.erase(std::unique(slabs.begin(), slabs.end(),
                            [&](const Box3& p, const Box3& q) { return key(p) == key(q); }),
                slabs.end());
    for (const Box3& slab : slabs) {
      if (!slab.empty()) w_.solids.push_back({slab, SolidKind::wall, {}});
    }
    const Eigen::Vector2d margin = Eigen::Vector2d::Constant(w_.wall_thickness);
    w_.bounds = {w_.rooms.front().rect.min - margin, w_.rooms.front().rect.max + margin};
    for (const Room& room : w_.rooms) {
      w_.bounds.min = w_.bounds.min.cwiseMin(room.rect.min - margin);
      w_.bounds.max = w_.bounds.max.cwiseMax(room.rect.max + margin);
    }
  }

  void add_structural_planes() {
    const double h = w_.height;
    std::vector<std::vector<Eigen::Vector3d>> floor, ceiling;
    for (const Room& room : w_.rooms) {
      floor.push_back(detail::face_rectangle(Face::pos_z, 0.0, room.rect.min, room.rect.max));
      ceiling.push_back(detail::face_rectangle(Face::neg_z, h, room.rect.min, room.rect.max));
    }
    for (const Doorway& door : w_.doorways) {
      floor.push_back(detail::face_rectangle(Face::pos_z, 0.0, door.opening.min, door.opening.max));
    }
    w_.floor_plane = detail::add_plane(w_, SemanticClass::floor, Face::pos_z, 0.0, std::move(floor),
                                       0, -1, "floor");
    w_.ceiling_plane = detail::add_plane(w_, SemanticClass::ceiling, Face::neg_z, h,
                                         std::move(ceiling), 0, w_.ceiling_material, "ceiling");

    static const char* kSideNames[4] = {"east wall", "west wall", "north wall", "south wall"};
    for (Room& room : w_.rooms) {
      for (int f = 0; f < 4; ++f) {
        const Face face = static_cast<Face>(f);
        const int axis = face_axis(face), along = 1 - axis;
        const double level = face_sign(face) > 0 ? room.rect.min[axis] : room.rect.max[axis];
        // Doorways in this wall, by position along it; the wall is cut around each.
        std::vector<const Doorway*> doors;
        for (const Doorway& door : w_.doorways) {
          const bool in_wall = door.passage_axis == axis &&
                               (door.opening.min[axis] == level || door.opening.max[axis] == level);
          if (in_wall && door.opening.min[along] < room.rect.max[along] &&
              door.opening.max[along] > room.rect.min[along]) {
            doors.push_back(&door);
          }
        }
        std::sort(doors.begin(), doors.end(), [&](const Doorway* p, const Doorway* q) {
          return p->opening.min[along] < q->opening.min[along];
        });
        std::vector<std::vector<Eigen::Vector3d>> pieces;
        auto piece = [&](double lo, double hi, double z0) {
          if (hi <= lo) return;
          Eigen::Vector2d a, b;  // (along-wall, z) in x, y, z order without the normal axis
          a = {lo, z0};
          b = {hi, w_.height};
          pieces.push_back(detail::face_rectangle(face, level, a, b));
        };
        double cursor = room.rect.min[along];
        for (const Doorway* door : doors) {
          piece(cursor, door->opening.min[along], 0.0);
          piece(door->opening.min[along], door->opening.max[along], door->height);
          cursor = door->opening.max[along];
        }
        piece(cursor, room.rect.max[along], 0.0);
        room.wall_planes[f] =
            detail::add_plane(w_, SemanticClass::wall, face, level, std::move(pieces), room.id,
                              room.wall_material, room.name + " " + kSideNames[f]);
      }
    }

    for (Doorway& door : w_.doorways) {
      const int axis = door.passage_axis, along = 1 - axis;
      const std::string name = "doorway " + std::to_string(door.id);
      for (int end = 0; end < 2; ++end) {
        const Face face = make_face(along, end == 0);
        const double level = end == 0 ? door.opening.min[along] : door.opening.max[along];
        const Eigen::Vector2d a(door.opening.min[axis], 0.0),
            b(door.opening.max[axis], door.height);
        door.jamb_planes[end] = detail::add_plane(
            w_, SemanticClass::wall, face, level, {detail::face_rectangle(face, level, a, b)},
            door.rooms[0], w_.room(door.rooms[0]).wall_material,
            name + (end == 0 ? " jamb low" : " jamb high"));
      }
      door.soffit_plane = detail::add_plane(
          w_, SemanticClass::wall, Face::neg_z, door.height,
          {detail::face_rectangle(Face::neg_z, door.height, door.opening.min, door.opening.max)},
          door.rooms[0], w_.room(door.rooms[0]).wall_material, name + " soffit");
    }
  }

  void build_route() {
    const double t = w_.wall_thickness;
    const double door_margin = 0.5 * t + kApproach;
    const double corridor_mid = 0.5 * metres(corridor_);
    auto door_y = [&](const Row& row) {
      return row.north ? metres(corridor_) + 0.5 * t : -0.5 * t;
    };
    std::vector<RouteVertex> route;
    auto add = [&](double x, double y, double margin) {
      const Eigen::Vector2d p(x, y);
      if (!route.empty() && (route.back().position - p).norm() < 1e-9) {
        route.back().straight_margin = std::max(route.back().straight_margin, margin);
        return;
      }
      route.push_back({p, margin});
    };
    // Traverses a row in the given direction: in through one corridor doorway, out the other.
    auto traverse = [&](const Row& row, bool eastwards) {
      const double in_x = eastwards ? row.west_door_x : row.east_door_x;
      const double out_x = eastwards ? row.east_door_x : row.west_door_x;
      add(in_x, door_y(row), door_margin);
      const double y = row.rooms.size() >= 2 ? row.chain_y : row.deep_y;
      add(in_x, y, 0.0);
      if (row.rooms.size() >= 2) {
        std::vector<double> chain_x;
        for (std::size_t i = 0; i + 1 < row.rooms.size(); ++i) {
          chain_x.push_back(w_.rooms[row.rooms[i]].rect.max.x() + 0.5 * t);
        }
        if (!eastwards) std::reverse(chain_x.begin(), chain_x.end());
        for (double x : chain_x) add(x, y, door_margin);
      }
      add(out_x, y, 0.0);
      add(out_x, door_y(row), door_margin);
    };
    if (rows_.size() == 2) {
      add(rows_[0].west_door_x, corridor_mid, 0.0);  // start: mid-way across the corridor
      traverse(rows_[0], true);
      add(rows_[0].east_door_x, corridor_mid, 0.0);
      add(rows_[1].east_door_x, corridor_mid, 0.0);
      traverse(rows_[1], false);
      add(rows_[1].west_door_x, corridor_mid, 0.0);
    } else {
      // One row: back along the corridor; start half-way along it.
      add(0.5 * (rows_[0].west_door_x + rows_[0].east_door_x), corridor_mid, 0.0);
      add(rows_[0].west_door_x, corridor_mid, 0.0);
      traverse(rows_[0], true);
      add(rows_[0].east_door_x, corridor_mid, 0.0);
    }
    if ((route.back().position - route.front().position).norm() < 1e-9) route.pop_back();
    // Drop collinear corners that are not doorways (straight crossings), except the start.
    std::vector<RouteVertex> simplified;
    const std::size_t n = route.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d prev = route[(i + n - 1) % n].position,
                            next = route[(i + 1) % n].position;
      const Eigen::Vector2d d1 = route[i].position - prev, d2 = next - route[i].position;
      const bool collinear = std::fabs(d1.x() * d2.y() - d1.y() * d2.x()) < 1e-12 && d1.dot(d2) > 0;
      if (i == 0 || route[i].straight_margin > 0 || !collinear) simplified.push_back(route[i]);
    }
    w_.route = std::move(simplified);
  }

  const BuildingParams& o_;
  Rng rng_;
  World w_;
  Units t_ = 0, corridor_ = 0, length_ = 0;
  std::vector<Row> rows_;
};

double polygon_area(const std::vector<Eigen::Vector3d>& polygon) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    sum += polygon[i].cross(polygon[(i + 1) % polygon.size()]);
  }
  return 0.5 * sum.norm();
}

}  // namespace

void BuildingParams::validate() const {
  auto range = [](double lo, double hi, const char* name) {
    require(std::isfinite(lo) && std::isfinite(hi) && lo > 0 && lo <= hi,
            std::string("BuildingParams: ") + name + " range [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "] is empty or not positive");
  };
  require(room_count >= 1 && room_count <= 10,
          "BuildingParams: room_count must be in 1..10, got " + std::to_string(room_count));
  range(min_room_side, max_room_side, "room side");
  range(min_ceiling, max_ceiling, "ceiling height");
  range(min_corridor_width, max_corridor_width, "corridor width");
  range(min_door_width, max_door_width, "door width");
  range(min_door_height, max_door_height, "door height");
  range(min_wall_thickness, max_wall_thickness, "wall thickness");
  require(grid_step > 0 && grid_step <= 0.1, "BuildingParams: grid_step must be in (0, 0.1] m");
  require(min_room_side >= 2.5, "BuildingParams: rooms need sides of at least 2.5 m");
  require(min_corridor_width >= 1.2, "BuildingParams: the corridor must be at least 1.2 m wide");
  require(0.4 * min_room_side >= kDoorMargin + 0.5 * max_door_width,
          "BuildingParams: doorways of max_door_width do not fit rooms of min_room_side");
  require(min_door_width >= 0.8,
          "BuildingParams: doorways narrower than 0.8 m do not let the robot pass");
  require(max_door_height + 0.2 <= min_ceiling,
          "BuildingParams: doorways must be at least 0.2 m lower than the ceiling");
  require(min_furniture >= 0 && min_furniture <= max_furniture && max_furniture <= 12,
          "BuildingParams: furniture count range must satisfy 0 <= min <= max <= 12");
  require(door_leaf_probability >= 0 && door_leaf_probability <= 1,
          "BuildingParams: door_leaf_probability must be in [0, 1]");
  require(tour_frames >= 0, "BuildingParams: tour_frames must be >= 0");
}

std::string to_string(FurnitureKind kind) {
  switch (kind) {
    case FurnitureKind::cabinet:
      return "cabinet";
    case FurnitureKind::table:
      return "table";
    case FurnitureKind::shelf:
      return "shelf";
    case FurnitureKind::crate:
      return "crate";
  }
  return "cabinet";
}

std::vector<Label> continuous_surface_ids(const World& world) {
  constexpr double kTolerance = 1e-6;  // metres: layout coordinates are exact multiples of 5 mm
  std::vector<Label> root(world.planes.size() + 1);
  std::iota(root.begin(), root.end(), Label{0});
  const auto find = [&](Label id) {
    while (root[id] != id) id = root[id] = root[root[id]];
    return id;
  };
  // Axis-aligned bounds of every polygon (the world's faces are axis-aligned rectangles, so two
  // coplanar ones touch exactly when their bounds do).
  std::vector<std::vector<Box3>> bounds(world.planes.size());
  for (std::size_t i = 0; i < world.planes.size(); ++i) {
    for (const auto& polygon : world.planes[i].polygons) {
      Box3 box{polygon.front(), polygon.front()};
      for (const Eigen::Vector3d& v : polygon) {
        box.min = box.min.cwiseMin(v);
        box.max = box.max.cwiseMax(v);
      }
      bounds[i].push_back(box);
    }
  }
  const auto touch = [&](const Box3& a, const Box3& b) {
    return ((a.min.array() - kTolerance) <= b.max.array()).all() &&
           ((b.min.array() - kTolerance) <= a.max.array()).all();
  };
  for (std::size_t i = 0; i < world.planes.size(); ++i) {
    for (std::size_t j = i + 1; j < world.planes.size(); ++j) {
      const Plane& a = world.planes[i];
      const Plane& b = world.planes[j];
      if (a.normal.dot(b.normal) < 1.0 - 1e-9 || std::fabs(a.offset - b.offset) > kTolerance)
        continue;
      bool touching = false;
      for (const Box3& box_a : bounds[i]) {
        for (const Box3& box_b : bounds[j]) touching = touching || touch(box_a, box_b);
      }
      if (!touching) continue;
      const Label ra = find(a.id), rb = find(b.id);
      root[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  for (Label id = 1; id < root.size(); ++id) root[id] = find(id);
  return root;
}

double Plane::area() const {
  double total = 0;
  for (const auto& polygon : polygons) total += polygon_area(polygon);
  return total;
}

// Called per pixel: the message is built only on failure.
const Plane& World::plane(Label id) const {
  if (id < 1 || id > planes.size()) throw Error("World: no plane " + std::to_string(id));
  return planes[id - 1];
}

const Room& World::room(Label id) const {
  if (id < 1 || id > rooms.size()) throw Error("World: no room " + std::to_string(id));
  return rooms[id - 1];
}

Label World::room_at(const Eigen::Vector2d& p) const {
  for (const Room& r : rooms) {
    if (r.rect.contains(p)) return r.id;
  }
  return 0;
}

int World::doorway_at(const Eigen::Vector2d& p) const {
  for (std::size_t i = 0; i < doorways.size(); ++i) {
    if (doorways[i].opening.contains(p)) return static_cast<int>(i);
  }
  return -1;
}

Label World::wall_plane_at(const Eigen::Vector3d& p, Face face) const {
  const int axis = face_axis(face);
  if (axis == 2) {
    if (face != Face::neg_z) return 0;
    const int d = doorway_at(p.head<2>());
    return d >= 0 ? doorways[d].soffit_plane : Label{0};
  }
  // Step off the face into the open space in front of it.
  Eigen::Vector2d q = p.head<2>();
  q[axis] += face_sign(face) * 1e-6;
  if (const int d = doorway_at(q); d >= 0 && doorways[d].passage_axis != axis) {
    return doorways[d].jamb_planes[face_sign(face) > 0 ? 0 : 1];
  }
  const Label r = room_at(q);
  return r ? rooms[r - 1].wall_planes[static_cast<int>(face)] : Label{0};
}

int World::floor_material_at(const Eigen::Vector2d& p) const {
  if (const Label r = room_at(p)) return rooms[r - 1].floor_material;
  if (const int d = doorway_at(p); d >= 0) return room(doorways[d].rooms[0]).floor_material;
  return rooms.empty() ? 0 : rooms.front().floor_material;
}

std::vector<Rect2> World::obstacle_footprints() const {
  std::vector<Rect2> footprints;
  for (const Furniture& item : furniture) footprints.push_back(item.footprint);
  for (const DoorLeaf& leaf : door_leaves) footprints.push_back(solids[leaf.solid].box.footprint());
  return footprints;
}

World make_building(std::uint64_t seed, const BuildingParams& options) {
  options.validate();
  return LayoutBuilder(seed, options).build();
}

double distance_to_surfaces(const World& world, const Eigen::Vector3d& p) {
  double best = std::min(std::abs(p.z()), std::abs(p.z() - world.height));
  for (const Solid& solid : world.solids) {
    const Eigen::Vector3d& lo = solid.box.min;
    const Eigen::Vector3d& hi = solid.box.max;
    const double outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
    const double depth_inside = std::min((p - lo).minCoeff(), (hi - p).minCoeff());
    best = std::min(best, outside > 0 ? outside : std::max(0.0, depth_inside));
  }
  return best;
}

RoutePath route_path(const World& world) {
  return RoutePath(world.route, kMaxTurnRadius);
}

}  // namespace kartograf::synth
