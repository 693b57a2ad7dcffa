#include "kartograf/rooms/voronoi_segmentation.hpp"

#include <chrono>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"

namespace kartograf::rooms {

LabelImage voronoi_cells(const OccupancyGrid& map, const VoronoiGraph& graph, const AreaLimits& room_area) {
  const int width = map.width(), height = map.height();
  require(graph.clearance.width() == width && graph.clearance.height() == height,
          "voronoi_cells: the Voronoi graph differs from the map in size");
  cv::Mat open(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) open.at<std::uint8_t>(y, x) = map.cells(x, y) == CellState::free ? 255 : 0;
  for (const CriticalLine& line : graph.critical_lines) {
    const cv::Point p(line.point.x(), line.point.y());
    cv::line(open, p, cv::Point(line.basis_a.x(), line.basis_a.y()), cv::Scalar(0), 1, cv::LINE_8);
    cv::line(open, p, cv::Point(line.basis_b.x(), line.basis_b.y()), cv::Scalar(0), 1, cv::LINE_8);
  }
  cv::Mat parts, stats, centroids;
  const int count = cv::connectedComponentsWithStats(open, parts, stats, centroids, 4, CV_32S);
  const double cell_area = map.resolution * map.resolution;
  std::vector<Label> label_of(static_cast<std::size_t>(count), 0);
  Label next = 0;
  for (int i = 1; i < count && next < 65535; ++i) {
    if (room_area.contains(stats.at<int>(i, cv::CC_STAT_AREA) * cell_area)) label_of[static_cast<std::size_t>(i)] = ++next;
  }
  LabelImage cells(width, height, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) cells(x, y) = label_of[static_cast<std::size_t>(parts.at<int>(y, x))];
  grow_rooms(cells, map);
  return cells;
}

RoomSegmentation segment_voronoi(const OccupancyGrid& map, const VoronoiParams& params) {
  const auto start = std::chrono::steady_clock::now();
  const std::string what = "Voronoi room segmentation";
  check_map(map, what);
  params.room_area.check(what);
  const OccupancyGrid work = params.furniture ? without_furniture(map, *params.furniture) : map;
  LabelImage rooms = voronoi_cells(work, build_voronoi_graph(work, params.graph), params.room_area);
  merge_voronoi_cells(rooms, work, params.merging);
  return finish_segmentation(std::move(rooms), room_cells(map, work, params.furniture), "voronoi",
                             start);
}

}  // namespace kartograf::rooms
