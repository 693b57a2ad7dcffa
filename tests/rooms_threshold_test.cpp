// Room segmentation by threshold sweeps (rooms/threshold_methods.hpp), the shared steps
// (component tree, wavefront growing, room records) and the method registry: hand-made maps with
// known rooms, errors, and the real ipa_room_segmentation maps.
#include <algorithm>
#include <set>

#include "kartograf/compute/context.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/outputs/room_io.hpp"
#include "kartograf/pipeline/map_pipeline.hpp"
#include "kartograf/rooms/component_tree.hpp"
#include "kartograf/rooms/furniture.hpp"
#include "kartograf/rooms/room_methods.hpp"
#include "kartograf/rooms/threshold_methods.hpp"
#include "room_test_maps.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using rooms::RoomMethod;

rooms::RoomMethodParams area_limits(double min_m2, double max_m2) {
  rooms::RoomMethodParams options;
  options.room_area = rooms::AreaLimits{min_m2, max_m2};
  return options;
}

class ThresholdMethods : public ::testing::TestWithParam<RoomMethod> {};

TEST_P(ThresholdMethods, SplitRoomsInARowAtTheirDoorways) {
  LabelImage truth;
  const OccupancyGrid map = testing::rooms_in_a_row(3, &truth);
  const rooms::RoomSegmentation result =
      rooms::segment_rooms(compute::Context::cpu(), map, GetParam());
  ASSERT_EQ(result.records.size(), 3u);
  testing::expect_free_space_covered(map, result.rooms);
  const auto scores = eval::evaluate_room_segmentation(truth, result.rooms);
  // Only the doorway cells (18 x 2 per doorway, in no true room) can go either way.
  EXPECT_EQ(scores.recall_mean, 1.0);
  EXPECT_GT(scores.precision_mean, 0.99);
  // Rooms are 120 x 120 cells = 36 m^2 plus at most their doorways' cells.
  for (const rooms::RoomRecord& r : result.records) {
    EXPECT_GE(r.area_m2, 36.0);
    EXPECT_LE(r.area_m2, 36.0 + 2 * 18 * 2 * 0.0025);
  }
  // The middle room touches both others, through one doorway each, 0.9 m wide (the border the
  // split leaves may run a cell beyond it diagonally).
  const rooms::RoomRecord& middle = result.records[1];
  EXPECT_EQ(middle.neighbours, (std::vector<Label>{1, 3}));
  for (const rooms::Doorway& d : middle.doorways) {
    EXPECT_GE(d.width_m, 0.9 - 1e-9);
    EXPECT_LE(d.width_m, 1.05 + 1e-9);
  }
}

TEST_P(ThresholdMethods, FindRoomsOffACorridor) {
  LabelImage truth;
  const OccupancyGrid map = testing::rooms_off_a_corridor(4, &truth);
  const rooms::RoomSegmentation result =
      rooms::segment_rooms(compute::Context::cpu(), map, GetParam());
  testing::expect_free_space_covered(map, result.rooms);
  const auto scores = eval::evaluate_room_segmentation(truth, result.rooms);
  EXPECT_EQ(scores.segments, 5);
  EXPECT_GT(scores.recall_mean, 0.97);
  EXPECT_GT(scores.precision_mean, 0.97);
}

TEST_P(ThresholdMethods, RejectBadMaps) {
  OccupancyGrid empty;
  EXPECT_ERROR_MENTIONS(rooms::segment_rooms(compute::Context::cpu(), empty, GetParam()), "empty");
  OccupancyGrid walls = testing::carve_map(10, 10, {});
  EXPECT_ERROR_MENTIONS(rooms::segment_rooms(compute::Context::cpu(), walls, GetParam()),
                        "no free cell");
  OccupancyGrid bad_resolution = testing::rooms_in_a_row(1);
  bad_resolution.resolution = 0;
  EXPECT_ERROR_MENTIONS(rooms::segment_rooms(compute::Context::cpu(), bad_resolution, GetParam()),
                        "resolution", "> 0");
  EXPECT_ERROR_MENTIONS(rooms::segment_rooms(compute::Context::cpu(), testing::rooms_in_a_row(1),
                                             GetParam(), area_limits(5, 2)),
                        "area limits");
}

TEST_P(ThresholdMethods, AreaLimitsDecideWhatIsARoom) {
  // Two 36 m^2 rooms: with rooms of 40-100 m^2 only both together are one; with the default
  // limits (at most 47 m^2 morphological, 163 m^2 distance) the sweeps find each.
  const OccupancyGrid map = testing::rooms_in_a_row(2);
  EXPECT_EQ(rooms::segment_rooms(compute::Context::cpu(), map, GetParam(), area_limits(40, 100))
                .records.size(),
            1u);
  EXPECT_EQ(rooms::segment_rooms(compute::Context::cpu(), map, GetParam()).records.size(), 2u);
}

INSTANTIATE_TEST_SUITE_P(Rooms, ThresholdMethods,
                         ::testing::Values(RoomMethod::morphological, RoomMethod::distance),
                         [](const auto& info) { return rooms::to_string(info.param); });

TEST(RoomMethods, ParseNamesAndRejectUnknownOnes) {
  for (const RoomMethod m : rooms::all_room_methods())
    EXPECT_EQ(rooms::parse_room_method(rooms::to_string(m)), m);
  EXPECT_ERROR_MENTIONS(rooms::parse_room_method("watershed"), "watershed", "morphological");
}

TEST(ComponentTree, NestsTheComponentsOfEveryThreshold) {
  // Two peaks (levels 3 and 2) on a plateau of level 1, joined at level 1 only.
  Image<std::int32_t> levels(7, 1, 0);
  const int row[7] = {1, 3, 3, 1, 2, 1, 0};
  for (int x = 0; x < 7; ++x) levels(x, 0) = row[x];
  const rooms::ComponentTree tree = rooms::build_component_tree(levels);
  ASSERT_EQ(tree.nodes.size(), 3u);  // {3,3}, {2}, and the plateau {all but the last}
  std::multiset<std::pair<int, std::uint32_t>> nodes;
  for (const auto& n : tree.nodes) nodes.insert({n.level, n.cells});
  EXPECT_EQ(nodes, (std::multiset<std::pair<int, std::uint32_t>>{{3, 2}, {2, 1}, {1, 6}}));
  const int root = static_cast<int>(tree.nodes.size()) - 1;
  EXPECT_EQ(tree.nodes[root].parent, -1);
  EXPECT_EQ(tree.nodes[0].parent, root);
  EXPECT_EQ(tree.nodes[1].parent, root);
  EXPECT_EQ(tree.pixels_of(root).size(), 6u);
  EXPECT_EQ(tree.node_of[6], -1);
}

TEST(GrowRooms, FillsFreeCellsFromTheNearestRoomOnly) {
  OccupancyGrid map = testing::carve_map(10, 3, {{0, 0, 4, 3}, {5, 0, 10, 3}});  // wall at x = 4
  LabelImage labels(10, 3, 0);
  labels(0, 1) = 1;
  labels(9, 1) = 2;
  rooms::grow_rooms(labels, map);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 10; ++x)
      EXPECT_EQ(labels(x, y), x < 4 ? 1 : x == 4 ? 0 : 2) << x << "," << y;
  }
}

TEST(GrowRooms, ByClearanceRoomsMeetAtTheDoorway) {
  // A hall (100 x 60 cells) and a small room (30 x 30) beside it, joined by a 10-cell doorway in a
  // one-cell wall; seeds in the middle of each, as the methods' room centres are.
  const OccupancyGrid map =
      testing::carve_map(132, 62, {{1, 1, 101, 61}, {102, 1, 131, 31}, {101, 16, 102, 26}});
  LabelImage seeds(132, 62, 0);
  for (int y = 25; y < 35; ++y)
    for (int x = 45; x < 55; ++x) seeds(x, y) = 1;
  seeds(116, 15) = 2;
  LabelImage wavefront = seeds, by_clearance = seeds;
  rooms::grow_rooms(wavefront, map);
  rooms::grow_rooms_by_clearance(by_clearance, map, rooms::clearance(map));
  int hall_cells_to_room = 0, hall_cells_to_room_wavefront = 0;
  for (int y = 1; y < 61; ++y) {
    for (int x = 1; x < 101; ++x) {
      hall_cells_to_room += by_clearance(x, y) == 2;
      hall_cells_to_room_wavefront += wavefront(x, y) == 2;
    }
  }
  EXPECT_LE(hall_cells_to_room, 10);             // at most a few cells in the doorway's mouth
  EXPECT_GT(hall_cells_to_room_wavefront, 500);  // the wavefront spills into the hall
  for (int y = 1; y < 31; ++y)
    for (int x = 102; x < 131; ++x) EXPECT_EQ(by_clearance(x, y), 2);
}

// Rooms take the cells their walls enclose (a table, floor nobody saw), never the outside.
TEST(GrowRooms, RoomsTakeWhatTheirWallsEncloseButNotTheOutside) {
  // 12 x 7 cells: room 1 in x 1..4, room 2 in x 6..10, walls (not fillable) around and between;
  // a hole in room 1 at (2..3, 3), a gap in room 2's east wall that lets the outside in at (11, 3).
  LabelImage rooms(12, 7, 0);
  Image<std::uint8_t> fillable(12, 7, 1);
  for (int y = 0; y < 7; ++y) {
    for (int x = 0; x < 12; ++x) {
      const bool wall = x == 0 || x == 5 || (x == 11 && y != 3) || y == 0 || y == 6;
      fillable(x, y) = !wall;
      if (!wall && x < 5 && !(y == 3 && (x == 2 || x == 3))) rooms(x, y) = 1;
      if (!wall && x > 5 && x < 11 && !(x >= 8 && y >= 2 && y <= 4)) rooms(x, y) = 2;
    }
  }
  // Room 2's unlabelled patch (8..10, 2..4) touches the gap at (11, 3): the outside.
  const std::size_t taken = rooms::extend_rooms_over_enclosed(rooms, fillable);
  EXPECT_EQ(rooms(2, 3), 1);
  EXPECT_EQ(rooms(3, 3), 1);
  EXPECT_EQ(taken, 2u);
  for (int y = 2; y <= 4; ++y)
    for (int x = 8; x <= 10; ++x) EXPECT_EQ(rooms(x, y), 0) << x << "," << y;
  EXPECT_EQ(rooms(11, 3), 0);
  EXPECT_EQ(rooms(0, 3), 0);  // walls stay
  EXPECT_ERROR_MENTIONS(rooms::extend_rooms_over_enclosed(rooms, Image<std::uint8_t>(3, 3, 1)),
                        "differs");
}

// A small room touching a big one directly is a fragment of it; one behind a wall stays.
TEST(GrowRooms, SmallFragmentsJoinTheRoomTheyTouch) {
  LabelImage rooms(20, 10, 0);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) {
      if (x < 12) rooms(x, y) = 1;
      if (x >= 12 && x < 15 && y < 3) rooms(x, y) = 2;  // 9 cells touching room 1
      if (x >= 17 && y < 3) rooms(x, y) = 3;            // 9 cells, cells of no room between
    }
  }
  const double cell_area = 0.05 * 0.05;
  EXPECT_EQ(rooms::merge_room_fragments(rooms, cell_area, 10 * cell_area), 1);
  EXPECT_EQ(rooms(13, 1), 1);
  EXPECT_EQ(rooms(18, 1), 3);
  // Below the area limit nothing merges.
  rooms(13, 1) = 4;
  EXPECT_EQ(rooms::merge_room_fragments(rooms, cell_area, 0.5 * cell_area), 0);
  EXPECT_EQ(rooms(13, 1), 4);
}

// An open door's leaf in a corridor that no view saw round (a diagonal strip of unknown cells
// from the corridor's wall) is no obstacle to the rooms; the unknown outside (it reaches the map's
// border) and an unseen patch larger than the limit stay unknown.
TEST(GrowRooms, SmallUnseenIslandsAreFree) {
  // A corridor 8 x 1.6 m (160 x 32 cells) inside walls, the outside unknown all round.
  OccupancyGrid map = testing::carve_map(170, 42, {{5, 5, 165, 37}});
  for (int y = 0; y < 42; ++y) {
    for (int x = 0; x < 170; ++x) {
      const bool wall = (x == 4 || x == 165) && y >= 4 && y <= 37;
      const bool wall_row = (y == 4 || y == 37) && x >= 4 && x <= 165;
      if (wall || wall_row)
        map.cells(x, y) = CellState::occupied;
      else if (x < 4 || x > 165 || y < 4 || y > 37)
        map.cells(x, y) = CellState::unknown;
    }
  }
  // The leaf: 3 cells wide, from the south wall at x = 40 up and east for 16 rows (0.8 m).
  for (int k = 0; k < 16; ++k)
    for (int w = 0; w < 3; ++w) map.cells(40 + k + w, 36 - k) = CellState::unknown;
  // An unseen patch of 1 m^2 (20 x 20 cells) at the corridor's east end.
  for (int y = 10; y < 30; ++y)
    for (int x = 140; x < 160; ++x) map.cells(x, y) = CellState::unknown;
  OccupancyGrid freed = map;
  EXPECT_EQ(rooms::free_unseen_islands(freed, 0.5), 48u);
  EXPECT_EQ(freed.cells(41, 36), CellState::free);
  EXPECT_EQ(freed.cells(55, 22), CellState::free);
  EXPECT_EQ(freed.cells(150, 20), CellState::unknown);  // 1 m^2: larger than the limit
  EXPECT_EQ(freed.cells(0, 0), CellState::unknown);     // the outside
  EXPECT_EQ(freed.cells(4, 20), CellState::occupied);   // walls stay
  OccupancyGrid all = map;
  EXPECT_EQ(rooms::free_unseen_islands(all, 1.01), 48u + 400u);
  EXPECT_ERROR_MENTIONS(rooms::free_unseen_islands(map, -1.0), "largest island");
}

// A corridor whose middle no view saw (the robot looked into it from its ends only; survey seed
// 36): 0.75 m^2 of unknown cells from wall to wall cut it in two. With the map pipeline's limit
// they are free, and the corridor is one room.
TEST(GrowRooms, ACorridorsUnseenMiddleDoesNotSplitIt) {
  // A corridor 8 x 1.5 m (160 x 30 cells) inside walls, the outside unknown all round.
  OccupancyGrid map = testing::carve_map(170, 40, {{5, 5, 165, 35}});
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 170; ++x) {
      if (x < 4 || x > 165 || y < 4 || y > 35)
        map.cells(x, y) = CellState::unknown;
      else if (x == 4 || x == 165 || y == 4 || y == 35)
        map.cells(x, y) = CellState::occupied;
    }
  }
  for (int y = 5; y < 35; ++y)
    for (int x = 80; x < 90; ++x) map.cells(x, y) = CellState::unknown;  // 10 x 30 cells
  const double limit = pipeline::MapPipelineParams{}.room_unseen_island_m2;
  OccupancyGrid freed = map;
  EXPECT_EQ(rooms::free_unseen_islands(freed, limit), 300u);
  const auto rooms_of = [](const OccupancyGrid& m) {
    return rooms::segment_rooms(compute::Context::cpu(), m, RoomMethod::distance).records.size();
  };
  EXPECT_EQ(rooms_of(freed), 1u);
  OccupancyGrid half_metre = map;
  rooms::free_unseen_islands(half_metre, 0.5);
  EXPECT_EQ(rooms_of(half_metre), 2u);  // the limit before
}

TEST(GrowRooms, ClearanceIsTheDistanceToTheNearestObstacle) {
  const OccupancyGrid map = testing::carve_map(9, 5, {{1, 1, 8, 4}});
  const Image<float> c = rooms::clearance(map);
  EXPECT_FLOAT_EQ(c(0, 0), 0);
  EXPECT_NEAR(c(1, 1), 1, 1e-3);
  EXPECT_NEAR(c(4, 2), 2, 1e-3);
}

TEST(Furniture, FreeStandingObstaclesAreRemovedWallsStay) {
  // A 6 x 4 m room (120 x 80 cells) with a table (0.5 x 0.5 m), a cupboard against the wall and
  // a long partition wall (3 m) standing free.
  OccupancyGrid map = testing::carve_map(124, 84, {{2, 2, 122, 82}});
  const auto block = [&](int x0, int y0, int x1, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) map.cells(x, y) = CellState::occupied;
  };
  block(30, 30, 40, 40);  // table
  block(2, 50, 12, 60);   // cupboard touching the left wall
  block(60, 20, 62, 80);  // partition 3 m long
  const OccupancyGrid cleaned = rooms::without_furniture(map);
  EXPECT_EQ(cleaned.cells(35, 35), CellState::free);
  EXPECT_EQ(cleaned.cells(5, 55), CellState::occupied);
  EXPECT_EQ(cleaned.cells(61, 50), CellState::occupied);
  EXPECT_EQ(cleaned.cells(0, 0), CellState::occupied);
  EXPECT_ERROR_MENTIONS(rooms::without_furniture(map, {-1, 2}), "furniture limits");
}

TEST(Furniture, KeepsRoomsWholeWithTheFurnitureInThem) {
  // Three 6 x 6 m rooms; in the first, a ring of chairs (0.3 m blocks 0.15 m apart) around a
  // table (0.6 m): without the furniture step the inside of the ring becomes a room of its own.
  OccupancyGrid map = testing::rooms_in_a_row(3);
  const auto block = [&](int x0, int y0, int size) {
    for (int y = y0; y < y0 + size; ++y)
      for (int x = x0; x < x0 + size; ++x) map.cells(x, y) = CellState::occupied;
  };
  block(56, 56, 12);  // table
  for (int k = 0; k < 6; ++k) {
    block(38 + 9 * k, 38, 6), block(38 + 9 * k, 83, 6);
    block(38, 38 + 9 * k, 6), block(83, 38 + 9 * k, 6);
  }
  rooms::MorphologicalParams as_reference;
  as_reference.furniture.reset();
  const auto reference = rooms::segment_morphological(map, as_reference);
  const auto ours = rooms::segment_morphological(map);
  EXPECT_EQ(reference.records.size(), 4u);
  ASSERT_EQ(ours.records.size(), 3u);
  EXPECT_NE(ours.rooms(50, 60), 0);  // the cells between chairs and table are in the room
  EXPECT_EQ(ours.rooms(50, 60), ours.rooms(10, 10));
  EXPECT_EQ(ours.rooms(60, 60), ours.rooms(10, 10));  // and so is the table
  EXPECT_NE(reference.rooms(50, 60), reference.rooms(10, 10));
  EXPECT_EQ(reference.rooms(60, 60), 0);
  rooms::MorphologicalParams furniture_in_no_room;
  furniture_in_no_room.furniture->in_rooms = false;
  const auto apart = rooms::segment_morphological(map, furniture_in_no_room);
  EXPECT_EQ(apart.records.size(), 3u);
  EXPECT_EQ(apart.rooms(60, 60), 0);
  EXPECT_EQ(apart.rooms(50, 60), apart.rooms(10, 10));
}

// The 10 real maps of the benchmark, plain and furnished, against the survey's reference
// implementation's mean recall / precision (morphological 98.1 / 88.5 plain, 84.6 / 90.5
// furnished; distance 96.9 / 88.4 and 76.1 / 88.4), which ours must match or beat.
TEST(ThresholdMethodsOnRealMaps, MatchOrBeatTheReference) {
  struct Reference {
    RoomMethod method;
    std::string variant;
    double recall, precision;
  };
  const Reference references[] = {{RoomMethod::morphological, "plain", 0.981, 0.885},
                                  {RoomMethod::morphological, "furnitures", 0.846, 0.905},
                                  {RoomMethod::distance, "plain", 0.969, 0.884},
                                  {RoomMethod::distance, "furnitures", 0.761, 0.884}};
  for (const Reference& reference : references) {
    const std::string name = rooms::to_string(reference.method);
    const testing::BenchmarkMeans means =
        testing::benchmark_means(name, reference.variant, [&](const OccupancyGrid& map) {
          return rooms::segment_rooms(compute::Context::cpu(), map, reference.method);
        });
    ASSERT_EQ(means.maps, 10);
    EXPECT_GE(means.recall, reference.recall) << name << " " << reference.variant;
    EXPECT_GE(means.precision, reference.precision) << name << " " << reference.variant;
  }
}

}  // namespace
}  // namespace kartograf
