// The Voronoi graph room segmentation (rooms/voronoi_segmentation.hpp) and its parts: the exact
// nearest-obstacle transform, the pruned Voronoi graph with its critical lines, the cell merging;
// hand-made maps with known rooms, errors, and the real ipa_room_segmentation maps.
#include <algorithm>
#include <cmath>
#include <random>

#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/rooms/voronoi_segmentation.hpp"
#include "room_test_maps.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

// rooms_in_a_row: rooms of 120 x 120 cells, walls 2 cells thick, doorways 18 cells wide in rows
// [53, 71); the doorway between rooms k and k + 1 is columns [122 k, 122 k + 2).
constexpr int kDoorRow0 = 53, kDoorRow1 = 71;

TEST(NearestObstacles, MatchesBruteForce) {
  std::mt19937 rng(7);
  Image<std::uint8_t> free_cells(23, 17, 1);
  for (auto& c : free_cells.pixels()) c = rng() % 5 == 0 ? 0 : 1;
  const rooms::NearestObstacles near = rooms::nearest_obstacles(free_cells);
  for (int y = 0; y < free_cells.height(); ++y) {
    for (int x = 0; x < free_cells.width(); ++x) {
      // Brute force over the map's obstacles and the ring of cells just outside it.
      double best = 1e18;
      for (int oy = -1; oy <= free_cells.height(); ++oy) {
        for (int ox = -1; ox <= free_cells.width(); ++ox) {
          const bool inside =
              ox >= 0 && oy >= 0 && ox < free_cells.width() && oy < free_cells.height();
          if (inside && free_cells(ox, oy)) continue;
          best = std::min(best, double(ox - x) * (ox - x) + double(oy - y) * (oy - y));
        }
      }
      const float expected = free_cells(x, y) ? static_cast<float>(std::sqrt(best)) : 0.0f;
      ASSERT_FLOAT_EQ(near.clearance(x, y), expected) << x << "," << y;
      const Eigen::Vector2i f = near.nearest(x, y);
      if (free_cells(x, y)) {
        EXPECT_EQ((f - Eigen::Vector2i(x, y)).squaredNorm(), best) << x << "," << y;
      }
    }
  }
}

TEST(VoronoiGraph, RunsThroughTheDoorAndCutsThere) {
  const OccupancyGrid map = testing::rooms_in_a_row(2);
  const rooms::VoronoiGraph graph = rooms::build_voronoi_graph(map);
  // The pruned graph crosses the doorway (columns 122-123) on its middle rows.
  int door_cells = 0;
  for (int y = kDoorRow0; y < kDoorRow1; ++y)
    door_cells += graph.graph(122, y) + graph.graph(123, y);
  EXPECT_GE(door_cells, 2);
  // Leaf branches are gone: no graph cell lies within 10 cells of a room corner.
  for (int y = 2; y < 12; ++y)
    for (int x = 2; x < 12; ++x) EXPECT_EQ(graph.graph(x, y), 0) << x << "," << y;
  // One critical line crosses the doorway straight from jamb to jamb.
  int door_lines = 0;
  for (const rooms::CriticalLine& line : graph.critical_lines) {
    if (line.point.x() < 121 || line.point.x() > 124) continue;
    ++door_lines;
    EXPECT_NEAR(line.clearance, 9.0, 1.0);
    EXPECT_GT(line.angle_deg, 150.0);
    for (const Eigen::Vector2i& b : {line.basis_a, line.basis_b}) {
      EXPECT_EQ(map.cells(b.x(), b.y()), CellState::occupied);
      EXPECT_TRUE(b.y() == kDoorRow0 - 1 || b.y() == kDoorRow1) << b.transpose();
    }
  }
  EXPECT_EQ(door_lines, 1);
}

TEST(VoronoiSegmentation, SplitsTwoRoomsAtTheirDoor) {
  LabelImage truth;
  const OccupancyGrid map = testing::rooms_in_a_row(2, &truth);
  const rooms::RoomSegmentation result = rooms::segment_voronoi(map);
  EXPECT_EQ(result.method, "voronoi");
  ASSERT_EQ(result.records.size(), 2u);
  testing::expect_free_space_covered(map, result.rooms);
  const auto scores = eval::evaluate_room_segmentation(truth, result.rooms);
  EXPECT_EQ(scores.recall_mean, 1.0);
  EXPECT_GT(scores.precision_mean, 0.99);
  // The split lies in the doorway: room 1 ends and room 2 begins within its two columns.
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      if (result.rooms(x, y) == 1) {
        EXPECT_LT(x, 124) << x << "," << y;
      }
      if (result.rooms(x, y) == 2) {
        EXPECT_GE(x, 122) << x << "," << y;
      }
    }
  }
  ASSERT_EQ(result.records[0].neighbours, (std::vector<Label>{2}));
  EXPECT_NEAR(result.records[0].doorways[0].width_m, 0.9, 0.11);
}

TEST(VoronoiSegmentation, FindsRoomsOffACorridor) {
  LabelImage truth;
  const OccupancyGrid map = testing::rooms_off_a_corridor(4, &truth);
  const rooms::RoomSegmentation result = rooms::segment_voronoi(map);
  testing::expect_free_space_covered(map, result.rooms);
  const auto scores = eval::evaluate_room_segmentation(truth, result.rooms);
  // Every room comes out whole and nothing spills through a doorway...
  ASSERT_EQ(scores.room_recall.size(), 5u);
  for (int room = 0; room < 4; ++room)
    EXPECT_GT(scores.room_recall[static_cast<std::size_t>(room)], 0.99) << room;
  EXPECT_GT(scores.precision_mean, 0.99);
  // ...and the corridor, cut at every stretch of the graph, comes out whole again: its pieces share
  // borders as wide as the corridor (merging rule 3b).
  EXPECT_EQ(scores.segments, 5);
  EXPECT_GT(scores.room_recall[4], 0.97);
  // The reference's rules alone (rule 3b off) leave the corridor in pieces: a piece's border with
  // the next is < 20 % of its long perimeter.
  rooms::VoronoiParams reference;
  reference.merging.open_border_ratio = 0;
  const auto pieces =
      eval::evaluate_room_segmentation(truth, rooms::segment_voronoi(map, reference).rooms);
  EXPECT_GE(pieces.segments, 6);
  EXPECT_LT(pieces.room_recall[4], 0.9);
}

TEST(VoronoiCells, CutsMoreThanTheMergedResult) {
  const OccupancyGrid map = testing::rooms_off_a_corridor(4);
  const rooms::VoronoiGraph graph = rooms::build_voronoi_graph(map);
  LabelImage cells = rooms::voronoi_cells(map, graph, {0.1, 1e6});
  testing::expect_free_space_covered(map, cells);
  const int before = *std::max_element(cells.pixels().begin(), cells.pixels().end());
  EXPECT_GT(before, 5);  // the corridor comes in pieces before merging
  rooms::merge_voronoi_cells(cells, map);
  std::vector<Label> used(cells.pixels().begin(), cells.pixels().end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  EXPECT_LT(static_cast<int>(used.size()) - 1, before);
}

TEST(MergeVoronoiCells, JoinsTheHalvesOfASmallRoom) {
  // A 3 x 3 m room cut in two halves: each is small, has one neighbour and < 75 % wall (rule 1).
  const OccupancyGrid map = testing::carve_map(64, 64, {{2, 2, 62, 62}});
  LabelImage cells(64, 64, 0);
  for (int y = 2; y < 62; ++y)
    for (int x = 2; x < 62; ++x) cells(x, y) = x < 32 ? 1 : 2;
  rooms::merge_voronoi_cells(cells, map);
  EXPECT_EQ(cells(10, 10), cells(50, 50));
  EXPECT_NE(cells(10, 10), 0);
  // The halves of a long 25 x 3 m hall (> 12.5 m^2 each, sharing < 10 % of their perimeter) stay
  // apart under the reference's rules, but their border spans the hall's width: rule 3b joins them.
  const OccupancyGrid hall = testing::carve_map(504, 64, {{2, 2, 502, 62}});
  LabelImage halves(504, 64, 0);
  for (int y = 2; y < 62; ++y)
    for (int x = 2; x < 502; ++x) halves(x, y) = x < 252 ? 1 : 2;
  LabelImage reference_halves = halves;
  rooms::CellMergeParams reference;
  reference.open_border_ratio = 0;
  rooms::merge_voronoi_cells(reference_halves, hall, reference);
  EXPECT_EQ(reference_halves(10, 10), 1);
  EXPECT_EQ(reference_halves(400, 50), 2);
  rooms::merge_voronoi_cells(halves, hall);
  EXPECT_EQ(halves(10, 10), halves(400, 50));
}

TEST(MergeVoronoiCells, KeepsARoomApartFromItsCorridor) {
  // A 6 x 6 m room above a 1.6 m corridor cut in two pieces, the room opening onto the first piece
  // through a 0.9 m doorway: the corridor pieces join (border = the corridor's width), the room,
  // whose doorway is far narrower than the room, stays apart.
  const OccupancyGrid map =
      testing::carve_map(404, 160, {{2, 2, 122, 122}, {53, 122, 71, 124}, {2, 124, 402, 156}});
  LabelImage cells(404, 160, 0);
  for (int y = 2; y < 124; ++y)
    for (int x = 2; x < 122; ++x) cells(x, y) = map.cells(x, y) == CellState::free ? 1 : 0;
  for (int y = 124; y < 156; ++y)
    for (int x = 2; x < 402; ++x) cells(x, y) = x < 202 ? 2 : 3;
  rooms::merge_voronoi_cells(cells, map);
  EXPECT_EQ(cells(10, 130), cells(390, 150));
  EXPECT_NE(cells(60, 60), cells(10, 130));
  EXPECT_NE(cells(60, 60), 0);
}

TEST(VoronoiSegmentation, RejectsBadInput) {
  OccupancyGrid empty;
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi(empty), "Voronoi", "empty");
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi(testing::carve_map(10, 10, {})), "no free cell");
  OccupancyGrid bad_resolution = testing::rooms_in_a_row(1);
  bad_resolution.resolution = 0;
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi(bad_resolution), "resolution", "> 0");
  rooms::VoronoiParams bad_limits;
  bad_limits.room_area = {5, 2};
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi(testing::rooms_in_a_row(1), bad_limits),
                        "area limits");
  rooms::VoronoiParams bad_graph;
  bad_graph.graph.neighbourhood_index = 0;
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi(testing::rooms_in_a_row(1), bad_graph),
                        "neighbourhood_index");
  bad_graph = {};
  bad_graph.graph.min_angle_deg = 200;
  EXPECT_ERROR_MENTIONS(rooms::build_voronoi_graph(testing::rooms_in_a_row(1), bad_graph.graph),
                        "min_angle_deg");
  LabelImage wrong_size(3, 3, 0);
  EXPECT_ERROR_MENTIONS(rooms::merge_voronoi_cells(wrong_size, testing::rooms_in_a_row(1)), "size");
  rooms::VoronoiParams bad_merging;
  bad_merging.merging.open_border_ratio = -1;
  EXPECT_ERROR_MENTIONS(rooms::segment_voronoi(testing::rooms_in_a_row(1), bad_merging),
                        "open_border_ratio");
}

// The 10 real maps of the benchmark, plain and furnished. The survey's reference implementation
// reaches 95.0 / 94.8 % (plain) and 86.6 / 94.5 % (furnished) mean recall / precision; the issue
// asks the best method for 97 / 97 and 92 / 96; this one measured 97.4 / 97.1 and 92.4 / 96.8.
TEST(VoronoiSegmentationOnRealMaps, BeatsTheReference) {
  struct Variant {
    const char* name;
    double min_recall, min_precision;
  };
  for (const Variant& v : {Variant{"plain", 0.97, 0.97}, Variant{"furnitures", 0.92, 0.96}}) {
    const testing::BenchmarkMeans means = testing::benchmark_means(
        "voronoi", v.name, [](const OccupancyGrid& map) { return rooms::segment_voronoi(map); });
    ASSERT_EQ(means.maps, 10);
    EXPECT_GE(means.recall, v.min_recall) << v.name;
    EXPECT_GE(means.precision, v.min_precision) << v.name;
  }
}

// The graph's stretches count metres, not cells: the same building at 0.1 m and at 0.025 m a cell
// is cut where it is at 0.05 m. (With the reference's cell counts kept, office_e at 0.1 m lost
// 4 of its 32 segments, precision 0.911, and Freiburg101 at 0.025 m recall 0.877.)
TEST(VoronoiSegmentationOnRealMaps, HoldsAtOtherResolutions) {
  const auto voronoi = [](const OccupancyGrid& map) { return rooms::segment_voronoi(map); };
  const eval::RoomSegmentationScores coarse = testing::resampled_map_scores("office_e", 2, voronoi);
  EXPECT_GT(coarse.recall_mean, 0.97);     // measured 0.997 (0.995 at 0.05 m)
  EXPECT_GT(coarse.precision_mean, 0.95);  // measured 0.978 (0.982)
  const eval::RoomSegmentationScores fine =
      testing::resampled_map_scores("Freiburg101_scan", -2, voronoi);
  EXPECT_GT(fine.recall_mean, 0.93);     // measured 0.959 (0.976 at 0.05 m)
  EXPECT_GT(fine.precision_mean, 0.95);  // measured 0.978 (0.973)
}

}  // namespace
}  // namespace kartograf
