#include "room_test_maps.hpp"

#include <gtest/gtest.h>

#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/outputs/room_io.hpp"
#include "test_support_core.hpp"

namespace kartograf::testing {

namespace {

void fill(LabelImage& labels, const CellRect& r, Label label) {
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) labels(x, y) = label;
}

constexpr int kRoom = 120, kWall = 2, kDoor = 18;

}  // namespace

OccupancyGrid rooms_in_a_row(int rooms, LabelImage* truth) {
  const int width = kWall + rooms * (kRoom + kWall), height = kRoom + 2 * kWall;
  OccupancyGrid map = carve_map(width, height, {});
  if (truth) *truth = LabelImage(width, height, 0);
  const int door_y0 = kWall + (kRoom - kDoor) / 2;
  for (int k = 0; k < rooms; ++k) {
    const CellRect room{kWall + k * (kRoom + kWall), kWall, (k + 1) * (kRoom + kWall),
                        kWall + kRoom};
    fill(map.cells, room, CellState::free);
    if (truth) fill(*truth, room, static_cast<Label>(k + 1));
    if (k > 0)
      fill(map.cells, {room.x0 - kWall, door_y0, room.x0, door_y0 + kDoor}, CellState::free);
  }
  return map;
}

OccupancyGrid rooms_off_a_corridor(int rooms, LabelImage* truth) {
  constexpr int kCorridor = 32;
  const int width = kWall + rooms * (kRoom + kWall);
  const int height = kWall + kRoom + kWall + kCorridor + kWall;
  OccupancyGrid map = carve_map(width, height, {});
  if (truth) *truth = LabelImage(width, height, 0);
  const CellRect corridor{kWall, height - kWall - kCorridor, width - kWall, height - kWall};
  fill(map.cells, corridor, CellState::free);
  if (truth) fill(*truth, corridor, static_cast<Label>(rooms + 1));
  for (int k = 0; k < rooms; ++k) {
    const CellRect room{kWall + k * (kRoom + kWall), kWall, (k + 1) * (kRoom + kWall),
                        kWall + kRoom};
    fill(map.cells, room, CellState::free);
    if (truth) fill(*truth, room, static_cast<Label>(k + 1));
    const int door_x0 = room.x0 + (kRoom - kDoor) / 2;
    fill(map.cells, {door_x0, room.y1, door_x0 + kDoor, room.y1 + kWall}, CellState::free);
  }
  return map;
}

void expect_free_space_covered(const OccupancyGrid& map, const LabelImage& labels) {
  int unlabelled_free = 0, labelled_walls = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const bool free = map.cells.data()[i] == CellState::free;
    unlabelled_free += free && labels.data()[i] == 0;
    labelled_walls += !free && labels.data()[i] != 0;
  }
  EXPECT_EQ(unlabelled_free, 0);
  EXPECT_EQ(labelled_walls, 0);
}

namespace {

std::filesystem::path benchmark_folder() {
  return data_dir() / "ipa_room_maps" / "test_maps";
}

}  // namespace

BenchmarkMeans benchmark_means(const std::string& name, const std::string& variant,
                               const SegmentRooms& segment) {
  BenchmarkMeans means;
  for (const io::RoomMapCase& c : io::find_room_maps(benchmark_folder())) {
    if (c.variant != variant) continue;
    const rooms::RoomSegmentation result = segment(io::read_png_map(c.map));
    const eval::RoomSegmentationScores scores = eval::evaluate_room_segmentation(
        io::read_room_ground_truth_png(c.ground_truth), result.rooms);
    means.recall += scores.recall_mean;
    means.precision += scores.precision_mean;
    ++means.maps;
  }
  if (means.maps > 0) {
    means.recall /= means.maps;
    means.precision /= means.maps;
  }
  ::testing::Test::RecordProperty(name + "_" + variant + "_recall", std::to_string(means.recall));
  ::testing::Test::RecordProperty(name + "_" + variant + "_precision",
                                  std::to_string(means.precision));
  return means;
}

eval::RoomSegmentationScores benchmark_map_scores(const std::string& map,
                                                  const SegmentRooms& segment) {
  const rooms::RoomSegmentation result =
      segment(io::read_png_map(benchmark_folder() / (map + ".png")));
  const eval::RoomSegmentationScores scores = eval::evaluate_room_segmentation(
      io::read_room_ground_truth_png(benchmark_folder() / (map + "_gt_segmentation.png")),
      result.rooms);
  ::testing::Test::RecordProperty("recall", std::to_string(scores.recall_mean));
  ::testing::Test::RecordProperty("precision", std::to_string(scores.precision_mean));
  ::testing::Test::RecordProperty("seconds", std::to_string(result.seconds));
  return scores;
}

namespace {

// A coarse cell: free only where all four are, occupied where any is, else unknown.
OccupancyGrid coarsened(const OccupancyGrid& map) {
  OccupancyGrid out = map;
  out.resolution = 2 * map.resolution;
  out.cells = Image<CellState>(map.width() / 2, map.height() / 2, CellState::unknown);
  for (int y = 0; y < out.height(); ++y) {
    for (int x = 0; x < out.width(); ++x) {
      int free = 0, occupied = 0;
      for (int k = 0; k < 4; ++k) {
        const CellState c = map.cells(2 * x + k % 2, 2 * y + k / 2);
        free += c == CellState::free;
        occupied += c == CellState::occupied;
      }
      out.cells(x, y) = free == 4      ? CellState::free
                        : occupied > 0 ? CellState::occupied
                                       : CellState::unknown;
    }
  }
  return out;
}

LabelImage coarsened(const LabelImage& rooms) {
  LabelImage out(rooms.width() / 2, rooms.height() / 2, 0);
  for (int y = 0; y < out.height(); ++y) {
    for (int x = 0; x < out.width(); ++x) {
      const Label l = rooms(2 * x, 2 * y);
      const bool whole = rooms(2 * x + 1, 2 * y) == l && rooms(2 * x, 2 * y + 1) == l &&
                         rooms(2 * x + 1, 2 * y + 1) == l;
      out(x, y) = whole ? l : 0;
    }
  }
  return out;
}

template <class T>
Image<T> refined(const Image<T>& image) {
  Image<T> out(2 * image.width(), 2 * image.height());
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) out(x, y) = image(x / 2, y / 2);
  return out;
}

}  // namespace

eval::RoomSegmentationScores resampled_map_scores(const std::string& map, int factor,
                                                  const SegmentRooms& segment) {
  OccupancyGrid grid = io::read_png_map(benchmark_folder() / (map + ".png"));
  LabelImage truth =
      io::read_room_ground_truth_png(benchmark_folder() / (map + "_gt_segmentation.png"));
  if (factor == 2) {
    grid = coarsened(grid);
    truth = coarsened(truth);
  } else {
    EXPECT_EQ(factor, -2) << "resampled_map_scores: factor 2 or -2";
    grid.cells = refined(grid.cells);
    grid.resolution /= 2;
    truth = refined(truth);
  }
  const rooms::RoomSegmentation result = segment(grid);
  const eval::RoomSegmentationScores scores = eval::evaluate_room_segmentation(
      truth, result.rooms, eval::room_evaluation_params(grid.resolution));
  ::testing::Test::RecordProperty("recall", std::to_string(scores.recall_mean));
  ::testing::Test::RecordProperty("precision", std::to_string(scores.precision_mean));
  return scores;
}

}  // namespace kartograf::testing
