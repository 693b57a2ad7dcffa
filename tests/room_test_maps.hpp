#pragma once
// Hand-made occupancy maps with known rooms for the room segmentation tests: rectangles of free
// space carved out of an occupied map, and the ground truth that goes with them.
#include <functional>
#include <initializer_list>
#include <string>

#include "carved_map.hpp"
#include "kartograf/core/label_image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/rooms/room_segmentation.hpp"

namespace kartograf::testing {

// Rooms (6 x 6 m at 0.05 m/cell: 120 x 120 cells; two of them exceed the methods' largest room)
// in a row, walls 2 cells thick, each pair joined by a doorway 18 cells (0.9 m) wide and a wall
// thick, centred on the wall. Room k (1-based) is cells [2 + 122 (k - 1), 122 k) x [2, 122).
// truth: rooms labelled 1..n, doorways 0.
OccupancyGrid rooms_in_a_row(int rooms, LabelImage* truth = nullptr);

// A corridor 1.6 m wide (32 cells) along the bottom with `rooms` 6 x 6 m rooms above it, each
// opening onto it through a 0.9 m doorway. truth: the corridor is the last label.
OccupancyGrid rooms_off_a_corridor(int rooms, LabelImage* truth = nullptr);

// GoogleTest expectations: every free cell of the map has a room, no other cell has one.
void expect_free_space_covered(const OccupancyGrid& map, const LabelImage& labels);

// ---- The ipa benchmark maps (../shared/data/ipa_room_maps/test_maps) ----------------------------
using SegmentRooms = std::function<rooms::RoomSegmentation(const OccupancyGrid&)>;

// Mean recall and precision (the survey's numbers) of `segment` over every benchmark map of one
// variant (plain, furnitures, ...), recorded as test properties NAME_recall and NAME_precision.
struct BenchmarkMeans {
  double recall = 0, precision = 0;
  int maps = 0;
};
BenchmarkMeans benchmark_means(const std::string& name, const std::string& variant,
                               const SegmentRooms& segment);

// The scores of `segment` on one plain benchmark map (e.g. "office_c"), recorded as test
// properties recall, precision and seconds.
eval::RoomSegmentationScores benchmark_map_scores(const std::string& map,
                                                  const SegmentRooms& segment);

// The same map resampled by `factor` (2: 0.1 m cells, a cell free only where its four were, a
// room keeping only the cells whose four were its own; -2: 0.025 m, each cell split in four),
// scored as a map of that resolution (eval::room_evaluation_params); also returns the segments'
// count (at least 0.25 m^2 each) so that a caller can compare it with the original's.
eval::RoomSegmentationScores resampled_map_scores(const std::string& map, int factor,
                                                  const SegmentRooms& segment);

}  // namespace kartograf::testing
