#pragma once
// Room segmentation of 2-D occupancy maps (docs/methods.md M4): what every method returns, and the
// steps they share. A method labels the map's free cells with rooms 1..n (0: no room, e.g. walls,
// unknown space, free cells no room reaches); describe_rooms() measures the rooms.
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"

namespace kartograf::rooms {

// Room area limits [m^2]: a candidate region becomes a room only within them.
struct AreaLimits {
  double min_m2 = 0.0;
  double max_m2 = 0.0;
  bool contains(double area_m2) const { return area_m2 >= min_m2 && area_m2 <= max_m2; }
  // Throws Error naming `what` unless 0 <= min < max, both finite.
  void check(const std::string& what) const;
};

// Where two rooms meet: the cells of `room` whose 8-neighbours include cells of `other`, as a
// segment between the two that are farthest apart (map frame, metres) and its length.
struct Doorway {
  Label other = 0;
  Eigen::Vector2d from = Eigen::Vector2d::Zero();
  Eigen::Vector2d to = Eigen::Vector2d::Zero();
  double width_m = 0.0;
  int cells = 0;
};

struct RoomRecord {
  Label id = 0;
  double area_m2 = 0.0;
  int cells = 0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();    // map frame [m]
  Eigen::Vector2d min_corner = Eigen::Vector2d::Zero();  // bounding box, map frame [m]
  Eigen::Vector2d max_corner = Eigen::Vector2d::Zero();
  Eigen::Vector2i min_cell = Eigen::Vector2i::Zero();  // bounding box, (column, row), inclusive
  Eigen::Vector2i max_cell = Eigen::Vector2i::Zero();
  std::vector<Label> neighbours;  // ascending
  std::vector<Doorway> doorways;  // one per neighbour, same order
};

struct RoomSegmentation {
  LabelImage rooms;                 // the map's size; 0 = no room
  std::vector<RoomRecord> records;  // records[i].id == i + 1
  std::string method;
  double seconds = 0.0;  // the method's wall-clock time (map in memory)
};

// The rooms of a label image (labels 1..n, gaps allowed: records are renumbered 1..n in order of
// the labels, and `rooms` is relabelled to match).
std::vector<RoomRecord> describe_rooms(LabelImage& rooms, const OccupancyGrid& map);

// Grows labelled rooms over the free cells that have none, breadth first from every room at once
// through 8-neighbours (the reference's wavefront region growing): each free cell takes the room
// that reaches it first (ties: the room of the first neighbour in scan order). Free cells no room
// reaches stay 0.
void grow_rooms(LabelImage& rooms, const OccupancyGrid& map);

// Grows labelled rooms over the unlabelled cells marked in `fillable` (e.g. furniture and floor
// the sensor never saw, inside a room's walls) that are enclosed: their 4-connected component of
// unlabelled fillable cells does not reach the image border (which would make it the outside).
// Breadth first from every room at once through 4-neighbours; each cell takes the room that
// reaches it first. Components no room touches stay 0. Returns how many cells were taken.
std::size_t extend_rooms_over_enclosed(LabelImage& rooms, const Image<std::uint8_t>& fillable);

// Unknown cells in islands of at most max_area_m2 (8-connected components of unknown cells that do
// not reach the map's border) become free: what no view saw inside a room (the shadow of an open
// door's leaf or of a chair) must not narrow it for a segmentation that splits at narrowings.
// Returns how many cells became free.
std::size_t free_unseen_islands(OccupancyGrid& map, double max_area_m2);

// Rooms smaller than max_area_m2 that touch another room directly (4-neighbours, no wall or
// doorway between) are fragments of it: each joins the neighbour it shares the longest border
// with, smallest fragment first. Rooms behind walls and doorways stay, however small. Returns the
// number of rooms merged away (labels are not renumbered: describe_rooms does that).
int merge_room_fragments(LabelImage& rooms, double cell_area_m2, double max_area_m2);

// Euclidean distance [cells] of every free cell to the nearest cell that is not free (0 there);
// the map's outside counts as not free.
Image<float> clearance(const OccupancyGrid& map);

// Grows labelled rooms like grow_rooms, but floods the free cells in order of falling clearance
// (a watershed on the distance to obstacles): a cell is taken by the room that reaches it at the
// highest clearance, so rooms meet where the free space narrows (doorways) instead of wherever
// their wavefronts happen to meet. Clearances are compared in steps of 1/4 cell.
void grow_rooms_by_clearance(LabelImage& rooms, const OccupancyGrid& map,
                             const Image<float>& clearance);

// A method's result from its labels: labels on cells that are not free in `map` are cleared (a
// method may have segmented a copy without furniture, furniture.hpp), the rooms are described and
// numbered 1..n, and the time since `start` is recorded.
RoomSegmentation finish_segmentation(LabelImage rooms, const OccupancyGrid& map, std::string method,
                                     std::chrono::steady_clock::time_point start);

// Throws Error naming `what` when the map has no cell, no free cell or a resolution <= 0.
void check_map(const OccupancyGrid& map, const std::string& what);

}  // namespace kartograf::rooms
