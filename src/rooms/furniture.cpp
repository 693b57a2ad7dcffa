#include "kartograf/rooms/furniture.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"

namespace kartograf::rooms {

OccupancyGrid without_furniture(const OccupancyGrid& map, const FurnitureParams& params) {
  require(params.max_area_m2 >= 0 && params.max_extent_m >= 0,
          "without_furniture: furniture limits must be >= 0");
  const int width = map.width(), height = map.height();
  cv::Mat obstacles(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    std::uint8_t* row = obstacles.ptr<std::uint8_t>(y);
    for (int x = 0; x < width; ++x) row[x] = map.cells(x, y) == CellState::occupied ? 1 : 0;
  }
  cv::Mat labels, stats, centroids;
  const int count =
      cv::connectedComponentsWithStats(obstacles, labels, stats, centroids, 8, CV_32S);
  const double cell_area = map.resolution * map.resolution;
  std::vector<char> furniture(static_cast<std::size_t>(count), 0);
  for (int c = 1; c < count; ++c) {
    const int x = stats.at<int>(c, cv::CC_STAT_LEFT), y = stats.at<int>(c, cv::CC_STAT_TOP);
    const int w = stats.at<int>(c, cv::CC_STAT_WIDTH), h = stats.at<int>(c, cv::CC_STAT_HEIGHT);
    const bool at_border = x == 0 || y == 0 || x + w == width || y + h == height;
    const double extent = std::hypot(w, h) * map.resolution;
    furniture[static_cast<std::size_t>(c)] =
        !at_border && stats.at<int>(c, cv::CC_STAT_AREA) * cell_area <= params.max_area_m2 &&
        extent <= params.max_extent_m;
  }
  OccupancyGrid result = map;
  for (int y = 0; y < height; ++y) {
    const int* row = labels.ptr<int>(y);
    for (int x = 0; x < width; ++x) {
      if (furniture[static_cast<std::size_t>(row[x])]) result.cells(x, y) = CellState::free;
    }
  }
  return result;
}

const OccupancyGrid& room_cells(const OccupancyGrid& map, const OccupancyGrid& work,
                                const std::optional<FurnitureParams>& furniture) {
  return furniture && furniture->in_rooms ? work : map;
}

}  // namespace kartograf::rooms
