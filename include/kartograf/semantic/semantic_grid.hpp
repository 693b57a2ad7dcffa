#pragma once
// The hybrid metric-semantic grid of method M2 (docs/methods.md M2; Siemiatkowska et al.): a 2-D
// grid in which every cell holds the objects over it (label, outline in metres, height range, area)
// and a traversability weight in [0, 1] (floor 1, obstacles 0, doors 0.7: "slow near doors").
//
// Input: labelled 3-D points in a gravity-aligned world frame (metres, z up), e.g. frames
// back-projected with their pose and per-pixel classes, plus optional object detections. A cell
// sees floor evidence (floor points near the floor height) and obstacle evidence (any non-floor,
// non-ceiling point in the robot's height band above the floor). Cell classes, by priority:
//   obstacle evidence   -> the most frequent label of its band points (wall, door, furniture,
//                          unknown = an unclassified obstacle)
//   floor in a wall gap -> door: an open doorway, a gap of door width between two collinear
//                          straight wall pieces (the paper's "door adjacent to a wall")
//   floor               -> floor
//   nothing             -> unobserved (class unknown, weight NaN)
// Clean-up before objects: an obstacle cell that sees floor and only holds points spilled over
// from a surface on its boundary is floor; isolated obstacle cells are specks; furniture outlines
// are filled to their convex hull (table tops drop out of grazing views), and floor enclosed by a
// closed loop of unclassified obstacle cells (a table's edges labelled unknown) is an obstacle.
// Objects: straight wall pieces (wall cells grouped by their local direction), doorways (with
// centre and width), door leaves and furniture (connected components of their cells); detections
// add their own objects on the cells their footprint covers.
//
// Grid layout as core/occupancy_grid.hpp (ROS map_server): row 0 is the largest y, origin the
// lower-left corner of the lower-left cell, no rotation.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/color.hpp"
#include "kartograf/core/image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/core/semantic_class.hpp"

namespace kartograf::semantic {

inline constexpr float kUnobserved = std::numeric_limits<float>::quiet_NaN();

// Traversability per cell class; NaN = unknown (not observed). The unknown class also marks
// unclassified obstacles, which take `unclassified_obstacle`.
struct TraversabilityWeights {
  std::array<float, kSemanticClassCount> by_class = {
      kUnobserved,  // unknown
      1.0f,         // floor
      0.0f,         // wall
      0.0f,         // ceiling (never a cell class: ceiling points are above the robot)
      0.7f,         // door: slow near doors
      0.0f,         // furniture
  };
  float unclassified_obstacle = 0.0f;

  float of(SemanticClass c) const { return by_class[static_cast<std::size_t>(c)]; }
  // Throws Error unless every weight is NaN or in [0, 1].
  void validate() const;
};

struct SemanticGridParams {
  double resolution = 0.05;         // metres per cell
  std::optional<double> floor_z;    // default: floor_level of the floor points' z (else 0)
  std::optional<double> ceiling_z;  // default: median z of the ceiling points (else none)
  double floor_tolerance = 0.08;    // floor points within this of floor_z are floor evidence
  double band_min = 0.10;           // robot height band above the floor [m]: obstacles
  double band_max = 1.50;
  double ceiling_margin = 0.15;  // object heights count points below ceiling - this
  int min_obstacle_points = 2;   // per cell, fewer band points are noise
  // ... seen by at least this many views (when the points' views are known): one view alone
  // leaves streaks of edge artefacts along its rays (lateral noise at a wall's corner).
  int min_obstacle_views = 2;
  // ... and at least this many band points per floor point: a free cell seen many times gathers
  // a few stray (flying, mixed) points that must not make it an obstacle.
  double min_obstacle_floor_ratio = 0.25;
  // Spill: an obstacle cell that sees floor, with >= spill_fraction of its band points within
  // spill_margin of its side facing an obstacle cell with less floor, is free (a surface on the
  // cell boundary scatters noisy points into both cells). spill_margin 0: off.
  double spill_margin = 0.02;
  double spill_fraction = 0.8;
  bool remove_isolated_obstacles = true;
  // Wall cells beside floor are judged on the wall's face, measured on the wall points along a
  // stretch of it: a cell whose centre lies on the room's side of the face is floor.
  bool place_wall_faces = true;
  // Door leaf cells two or three deep are judged the same way on the leaf's face, measured on the
  // door points: a leaf is a few centimetres thick, and its face on a cell boundary made it two.
  bool place_leaf_faces = true;
  // A doorway is as deep as the walls seen from both sides are thick (when that was measured):
  // about the middle found across it, where its jambs were measured, and at least that deep where
  // it took the wall's rows beside it.
  bool doors_as_deep_as_walls = true;
  // Furniture outlines (legs, edges: a table top drops out at grazing views) are closed and
  // filled to their convex hull when that is at most this area [m^2]; 0: off.
  // The same bound holds for floor enclosed by unclassified obstacles.
  double max_furniture_fill_area = 4.0;  // obstacle cells without an obstacle neighbour: specks
  // A piece of furniture's outline is closed over gaps up to this long [m] before it is filled:
  // without phantom points (below) a table is its legs and the edge of its top nearest the views.
  double furniture_join_gap = 0.75;
  // Unclassified obstacles that stand free in a room as furniture does (a piece, closed over gaps
  // of a few cells, whose hull is at most max_furniture_fill_area, at most furniture_max_extent
  // long and whose points end furniture_max_height above the floor) are furniture: the views
  // label faces, and a table's legs, edges and grazing top are too thin or too noisy for a
  // region of their own. 0: off.
  double furniture_max_extent = 2.5;  // m
  double furniture_max_height = 2.1;  // m
  // A face of furniture size standing at most this far in front of a longer wall, with only
  // unseen cells between (a cabinet's front that the views took for a wall, its top and sides
  // hidden), is furniture, and so is the pocket behind it. So are the unseen cells at most this far
  // behind a furniture face the room saw, up to a wall or furniture (its top and back). 0: off.
  double furniture_max_depth = 1.0;  // m
  // Unobserved cells between the two faces of a wall (wall cells at most this far apart along a
  // row or a column, nothing seen between) are wall: its inside, which no view can see. 0: off.
  double max_wall_thickness = 0.35;  // m
  // Walls seen from one side only (a building's outer walls) extend into the unseen cells behind
  // them to the thickness of the walls seen from both sides, when there are such walls, and the
  // unseen block where two walls meet at a corner is wall: a wall is a solid, and its hidden back
  // is no more traversable than its face.
  bool back_one_sided_walls = true;
  // With the backs: a wall line runs on between two of its seen pieces (or to the wall it meets at
  // a corner) through up to this much of what no view saw or named [m]: a room's side the robot
  // never looked along (behind the furniture it turned away from, beyond its views' reach), where a
  // doorway would have shown floor. 0: off.
  double max_unseen_wall_gap = 3.0;
  // The cell lattice is shifted (less than a cell) so that wall faces lie on cell boundaries where
  // the faces are crisp (SemanticGrid::wall_face_crispness): a face inside a cell makes it half
  // wall, half room.
  bool align_cells_to_walls = true;
  // Unobserved cells between floor cells this close along a row or a column are floor: the thin
  // shadows behind corners that a camera turning in place leaves as a fan. 0: off.
  double max_floor_shadow = 0.15;  // m
  // An unobserved hole whose every neighbour is seen floor, or with seen floor at both ends of its
  // rows (or columns) and walls beside it, up to this area, is floor: nothing stands in it, or its
  // sides would have been seen from around it (the floor under and around a camera that turned in
  // place is out of its view; a stretch of corridor the views from its ends lost). 0: off.
  double max_floor_hole = 4.0;  // m^2
  // Free space from the views' rays (when their origins are known): every free_space_ray_stride-th
  // point's ray marks the slabs (free_space_slab high, from band_min) of the cells it crosses,
  // stopping free_space_end_margin x (1 + range) short of its point. Wall cells seen through below
  // them are no walls (a table's edge), and furniture fills the rectangle around its pieces but
  // for the floor seen through just under their tops (beside a table, not under it).
  // Wall cells whose wall points all come from views at least this far, seen through at every
  // height the views observe (a far wall's points that the depth camera's error put in front of
  // it), with floor seen in them and no furniture beside them, are floor [m]. 0: off. At 3 m the
  // free space's own end margin, free_space_end_margin x (1 + range), is two cells.
  double seen_through_wall_range = 3.0;
  // A wall or unclassified obstacle cell in which floor was seen and which was seen through at
  // every observable height, beside a wall cell with at least this many times its band points, is
  // floor: the depth noise of that wall's face spread into the room (a face's own cell holds its
  // points by the thousand, the spill a few percent of them). 0: off.
  double face_spill_ratio = 10.0;
  // An unobserved cell seen through at every observable height from band_min up is floor: nothing
  // stands in the robot's band there, and the floor runs on under the rays (a depth camera loses
  // the floor at grazing angles far off, while its rays to the walls behind pass low over it).
  // Neither this nor the floor's shadows and holes take a piece of unobserved cells in which the
  // views saw points more than floor_tolerance below the floor: a drop (stairs down), over which
  // rays pass as over lost floor. false: off.
  bool floor_seen_through = true;
  int free_space_ray_stride = 4;         // 0: no free space
  double free_space_slab = 0.02;         // m
  double free_space_end_margin = 0.025;  // m per m of range
  // Phantom points, the mixed pixels a depth camera returns on an object's outline, floating in the
  // air behind it: a band point (not wall or door) whose voxel of the free space above, and the
  // voxels phantom_margin beside it, the rays crossed more than phantom_pass_ratio times as often
  // as points fell in it gives no evidence (semantic/grid_phantoms.hpp). 0: off.
  double phantom_pass_ratio = 4;
  double phantom_margin = 0.02;  // m
  int min_floor_points = 1;
  double margin = 0.25;          // metres of grid around the data
  double min_wall_length = 0.5;  // shorter straight wall pieces are not objects
  double min_door_width = 0.4, max_door_width = 1.6;  // openings outside this are not doors
  // An open doorway is also found as a gap of door width between two collinear wall pieces
  // (their lines at most this far apart), with mostly observed floor along the gap.
  double max_wall_misalignment = 0.15;
  double min_gap_floor_fraction = 0.6;
  double door_passage_depth = 0.4;  // and no obstacle this far on either side of its middle
  TraversabilityWeights weights;

  void validate() const;  // throws Error naming the first bad field
};

// An object detected by other means (e.g. the Haar cascade): a footprint polygon in metres.
struct ObjectDetection {
  SemanticClass label = SemanticClass::unknown;
  std::string name;                        // e.g. "washbasin"
  std::vector<Eigen::Vector2d> footprint;  // polygon, >= 3 vertices
  double z_min = 0, z_max = 0;             // height range [m, world z]
  std::optional<float> weight;             // traversability of its cells; default: its label's
};

enum class ObjectKind : std::uint8_t { wall, doorway, door_leaf, furniture, detection };
std::string_view to_string(ObjectKind kind);

struct SemanticObject {
  int id = 0;  // 1-based: objects[id - 1]
  ObjectKind kind = ObjectKind::wall;
  SemanticClass label = SemanticClass::unknown;
  std::string name;                      // "wall 3", "doorway 1", "door 2", "furniture 4", ...
  std::vector<Eigen::Vector2d> contour;  // outline through its boundary cells' centres [m]
  double z_min = 0, z_max = 0;           // height range of its points (world z) [m]
  double area = 0;                       // footprint [m^2]
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  // Its extent along its main direction: a wall's line, a door's opening. width = |end - start|.
  Eigen::Vector2d axis_start = Eigen::Vector2d::Zero(), axis_end = Eigen::Vector2d::Zero();
  double width = 0;
  std::vector<Eigen::Vector2i> cells;  // (col, row)
};

// What a semantic grid inferred beyond the views: the wall thickness measured on walls seen from
// both sides and given to walls seen from one side (none: too few two-sided walls, none backed),
// and the cabinet fronts the views had taken for walls, the unseen pockets behind furniture faces
// filled as furniture, the furniture specks inside walls or on their faces made wall, the
// furniture cells in a wall's line behind furniture made wall, and the cells of the fronts'
// pockets made wall as the inside of a wall seen from its far side, the cells of room
// corners hidden behind furniture made wall, the cells of wall lines run on across what no
// view saw, the tables found by their legs, the cells a fill had joined to such a table made
// floor again, and the lone posts kept as obstacles (a leg inside one cell, no obstacle beside
// it, which the speck removal would have dropped), and the unobserved cells the views' rays
// crossed low made floor.
struct GridInferences {
  std::optional<double> wall_thickness;  // m
  // Where the cell lattice stands: the offset its boundaries moved by to lie on the wall faces (0
  // on an axis where they did not), and how crisp the faces across each axis were (the mean
  // resultant length of their points about each face's offset: 1 sharp, 0 spread over a cell or
  // no face; align_cells_to_walls moves for 0.29 and more).
  Eigen::Vector2d lattice_offset = Eigen::Vector2d::Zero();       // m
  Eigen::Vector2d wall_face_crispness = Eigen::Vector2d::Zero();  // per axis, 0..1
  int furniture_fronts = 0;
  int furniture_pockets = 0;
  int wall_specks = 0;
  int furniture_in_wall_lines = 0;
  int wall_insides_behind_fronts = 0;
  int wall_corners_behind_furniture = 0;
  int wall_cells_across_unseen = 0;
  int tables_on_legs = 0;
  int fill_cells_trimmed_at_tables = 0;
  int lone_posts_kept = 0;
  int floor_seen_through = 0;  // unobserved cells the rays crossed low: floor
};

struct SemanticGrid {
  double resolution = 0.05;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // lower-left corner [m]
  double floor_z = 0;
  std::optional<double> ceiling_z;
  Image<SemanticClass> classes;
  Image<float> weight;                   // [0, 1], NaN = unobserved
  Image<std::vector<int>> cell_objects;  // object ids over each cell
  std::vector<SemanticObject> objects;
  TraversabilityWeights weights;  // the table the cells were weighted with
  GridInferences inferred;

  int width() const { return classes.width(); }
  int height() const { return classes.height(); }
  bool contains(const Eigen::Vector2i& cell) const {
    return cell.x() >= 0 && cell.y() >= 0 && cell.x() < width() && cell.y() < height();
  }
  Eigen::Vector2d cell_center(const Eigen::Vector2i& cell) const {
    return origin + resolution * Eigen::Vector2d(cell.x() + 0.5, height() - cell.y() - 0.5);
  }
  Eigen::Vector2i cell_of(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d local = (p - origin) / resolution;
    return {static_cast<int>(std::floor(local.x())),
            height() - 1 - static_cast<int>(std::floor(local.y()))};
  }
  const SemanticObject& object(int id) const;  // throws Error for an unknown id
};

// Builds the grid. points[i] has class labels[i]; non-finite points are skipped. view_ids[i]
// (optional; ascending, e.g. LabelledViews::view_ids()) names the view that saw points[i]: then an
// obstacle cell must be seen by min_obstacle_views views (or by all, when there are fewer).
// view_origins[v] (optional; with view_ids) is where view v saw from: its rays give free space.
// Throws Error on mismatched sizes, bad options, no finite point, or a bad detection.
SemanticGrid build_semantic_grid(std::span<const Eigen::Vector3d> points,
                                 std::span<const SemanticClass> labels,
                                 const SemanticGridParams& options = {},
                                 std::span<const ObjectDetection> detections = {},
                                 std::span<const std::uint32_t> view_ids = {},
                                 std::span<const Eigen::Vector3d> view_origins = {});

// ---- Exports (data only; io/ writes the files) -----------------------------------------------

// Everything but the images, in plain fields: what the JSON export holds.
struct ObjectRecord {
  int id = 0;
  std::string kind;   // to_string(ObjectKind)
  std::string label;  // to_string(SemanticClass)
  std::string name;
  std::vector<Eigen::Vector2d> contour;
  double z_min = 0, z_max = 0, area = 0, width = 0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d axis_start = Eigen::Vector2d::Zero(), axis_end = Eigen::Vector2d::Zero();
  int cell_count = 0;
};
struct MapDescription {
  double resolution = 0;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  int width = 0, height = 0;
  double floor_z = 0;
  std::optional<double> ceiling_z;
  std::vector<std::pair<std::string, float>> class_weights;  // class name -> weight (NaN: unknown)
  std::array<int, kSemanticClassCount> cells_per_class{};
  int unobserved_cells = 0;
  GridInferences inferred;  // as SemanticGrid's
  std::vector<ObjectRecord> objects;
};
MapDescription describe(const SemanticGrid& grid);

// Colour of each class in the picture; unobserved cells are drawn `unobserved_colour`.
Rgb8 class_colour(SemanticClass c);
inline constexpr Rgb8 kUnobservedColour{60, 60, 60};

// The grid as a picture, `pixels_per_cell` pixels per cell (row 0 on top, as the grid), with a
// legend strip below it (a swatch and the name of each class and its weight).
struct MapPicture {
  RgbImage image;
  int pixels_per_cell = 1;
  int map_width = 0, map_height = 0;  // cells
};
MapPicture render_map(const SemanticGrid& grid, int pixels_per_cell = 2);

// Occupancy for io::write_ros_map: weight > 0 free, weight 0 occupied, unobserved unknown.
OccupancyGrid to_occupancy_grid(const SemanticGrid& grid);

// A graded costmap in the ROS costmap_2d convention: 0 = free (weight 1) .. 254 = lethal
// (weight 0), 255 = no information; cost = round(254 (1 - weight)).
Image<std::uint8_t> to_costmap(const SemanticGrid& grid);

}  // namespace kartograf::semantic
