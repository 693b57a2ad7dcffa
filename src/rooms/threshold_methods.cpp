#include "kartograf/rooms/threshold_methods.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/rooms/component_tree.hpp"

namespace kartograf::rooms {

namespace {

using Clock = std::chrono::steady_clock;

// Chessboard distance of every free cell to the nearest other cell (outside the map counts as
// free, as OpenCV's erosion treats the border): free cells touching an obstacle get 1.
Image<std::int32_t> chessboard_distance(const OccupancyGrid& map) {
  const int width = map.width(), height = map.height();
  constexpr std::int32_t kFar = 1 << 28;
  Image<std::int32_t> d(width, height);
  for (std::size_t i = 0; i < d.size(); ++i)
    d.data()[i] = map.cells.data()[i] == CellState::free ? kFar : 0;
  const auto at = [&](int x, int y) {
    return (x < 0 || y < 0 || x >= width || y >= height) ? kFar : d(x, y);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (d(x, y) == 0) continue;
      d(x, y) = std::min({d(x, y), at(x - 1, y) + 1, at(x - 1, y - 1) + 1, at(x, y - 1) + 1,
                          at(x + 1, y - 1) + 1});
    }
  }
  for (int y = height - 1; y >= 0; --y) {
    for (int x = width - 1; x >= 0; --x) {
      if (d(x, y) == 0) continue;
      d(x, y) = std::min({d(x, y), at(x + 1, y) + 1, at(x + 1, y + 1) + 1, at(x, y + 1) + 1,
                          at(x - 1, y + 1) + 1});
    }
  }
  for (std::int32_t& v : d.pixels()) v = std::min(v, 65535);
  return d;
}

// Labels the pixels of the chosen nodes 1..n (in node order) and grows them over the free space.
LabelImage rooms_of(const ComponentTree& tree, const std::vector<char>& chosen, int width,
                    int height, const OccupancyGrid& map, RoomGrowth growth) {
  std::vector<std::int32_t> room(tree.nodes.size(), 0);
  Label next = 0;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    if (chosen[i] && next < 65535) room[i] = ++next;
  }
  // Parents come after children: sweeping down from the roots hands each room to its subtree.
  for (std::size_t i = tree.nodes.size(); i-- > 0;) {
    const int p = tree.nodes[i].parent;
    if (room[i] == 0 && p >= 0) room[i] = room[static_cast<std::size_t>(p)];
  }
  LabelImage rooms(width, height, 0);
  for (std::size_t i = 0; i < rooms.size(); ++i) {
    if (tree.node_of[i] >= 0)
      rooms.data()[i] = static_cast<Label>(room[static_cast<std::size_t>(tree.node_of[i])]);
  }
  if (growth == RoomGrowth::clearance) {
    grow_rooms_by_clearance(rooms, map, clearance(map));
  } else {
    grow_rooms(rooms, map);
  }
  return rooms;
}

// The map a method segments: without its furniture when asked.
OccupancyGrid working_map(const OccupancyGrid& map,
                          const std::optional<FurnitureParams>& furniture) {
  return furniture ? without_furniture(map, *furniture) : map;
}

}  // namespace

RoomSegmentation segment_morphological(const OccupancyGrid& map,
                                       const MorphologicalParams& params) {
  const Clock::time_point start = Clock::now();
  check_map(map, "morphological room segmentation");
  params.room_area.check("morphological room segmentation");
  require(params.max_erosions >= 1, "morphological room segmentation: max_erosions must be >= 1");
  const OccupancyGrid work = working_map(map, params.furniture);
  const ComponentTree tree = build_component_tree(chessboard_distance(work));
  const double cell_area = map.resolution * map.resolution;
  // Erosion k leaves {distance > k}: node n (the component of {distance >= level}) is the
  // region of erosions parent level .. level - 1, first seen at erosion max(parent level, 1).
  // Walking down from the roots, the first node that fits (within max_erosions) is a room.
  std::vector<char> chosen(tree.nodes.size(), 0), taken(tree.nodes.size(), 0);
  for (std::size_t i = tree.nodes.size(); i-- > 0;) {
    const ComponentNode& node = tree.nodes[i];
    const bool below_room = node.parent >= 0 && taken[static_cast<std::size_t>(node.parent)];
    const int first_erosion =
        std::max(node.parent >= 0 ? tree.nodes[static_cast<std::size_t>(node.parent)].level : 0, 1);
    const bool fits = first_erosion <= params.max_erosions && first_erosion < node.level &&
                      params.room_area.contains(node.cells * cell_area);
    chosen[i] = !below_room && fits;
    taken[i] = below_room || fits;
  }
  return finish_segmentation(rooms_of(tree, chosen, map.width(), map.height(), work, params.growth),
                             room_cells(map, work, params.furniture), "morphological", start);
}

RoomSegmentation segment_distance_transform(const OccupancyGrid& map,
                                            const DistanceTransformParams& params) {
  const Clock::time_point start = Clock::now();
  check_map(map, "distance transform room segmentation");
  params.room_area.check("distance transform room segmentation");
  const int width = map.width(), height = map.height();
  const OccupancyGrid work = working_map(map, params.furniture);
  cv::Mat free(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x)
      free.at<std::uint8_t>(y, x) = work.cells(x, y) == CellState::free ? 255 : 0;
  }
  cv::erode(free, free, cv::Mat());
  cv::Mat distance;
  cv::distanceTransform(free, distance, cv::DIST_L2, 5);
  Image<std::int32_t> levels(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      levels(x, y) = std::min(255, static_cast<int>(std::lround(distance.at<float>(y, x))));
    }
  }
  const ComponentTree tree = build_component_tree(levels);
  const double cell_area = map.resolution * map.resolution;
  // Threshold t keeps {distance > t}: node n is the region of thresholds parent level .. level-1.
  std::vector<int> rooms_at(257, 0);
  for (const ComponentNode& node : tree.nodes) {
    if (!params.room_area.contains(node.cells * cell_area)) continue;
    const int low = node.parent >= 0 ? tree.nodes[static_cast<std::size_t>(node.parent)].level : 0;
    for (int t = std::max(low, 1); t < node.level && t <= 255; ++t)
      ++rooms_at[static_cast<std::size_t>(t)];
  }
  int best = 1;
  for (int t = 1; t <= 255; ++t) {
    if (rooms_at[static_cast<std::size_t>(t)] > rooms_at[static_cast<std::size_t>(best)]) best = t;
  }
  std::vector<char> chosen(tree.nodes.size(), 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const ComponentNode& node = tree.nodes[i];
    const int low = node.parent >= 0 ? tree.nodes[static_cast<std::size_t>(node.parent)].level : 0;
    chosen[i] = std::max(low, 1) <= best && best < node.level &&
                params.room_area.contains(node.cells * cell_area);
  }
  return finish_segmentation(rooms_of(tree, chosen, width, height, work, params.growth),
                             room_cells(map, work, params.furniture), "distance", start);
}

}  // namespace kartograf::rooms
