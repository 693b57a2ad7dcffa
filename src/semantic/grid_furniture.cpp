#include "semantic/grid_furniture.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "semantic/grid_cells.hpp"

namespace kartograf::semantic::detail {
namespace {

bool is_wall(const SemanticGrid& grid, int col, int row) {
  return seen_as(grid, {col, row}, SemanticClass::wall);
}

// Unseen cells on a row or column run of unseen cells with wall cells at both ends, longer than
// min_cells (a wall's inside) and at most max_cells: what lies between two faces.
cv::Mat pockets_between_walls(const SemanticGrid& grid, int min_cells, int max_cells) {
  cv::Mat pockets = cv::Mat::zeros(grid.height(), grid.width(), CV_8U);
  const auto wall_end = [&](const Eigen::Vector2i& c) { return is_wall(grid, c.x(), c.y()); };
  for (const Eigen::Vector2i& k : unobserved_runs_between(grid, wall_end, min_cells, max_cells))
    pockets.at<std::uint8_t>(k.y(), k.x()) = 255;
  return pockets;
}

// Connected pieces (8-neighbours) of a mask: a label image and each piece's cells.
struct Pieces {
  cv::Mat labels;
  std::vector<std::vector<cv::Point>> cells;  // index = label; 0 is the background
};

Pieces pieces_of(const cv::Mat& mask) {
  Pieces p;
  const int count = cv::connectedComponents(mask, p.labels, 8, CV_32S);
  p.cells.resize(static_cast<std::size_t>(count));
  for (int row = 0; row < mask.rows; ++row)
    for (int col = 0; col < mask.cols; ++col)
      if (const int l = p.labels.at<int>(row, col); l > 0)
        p.cells[static_cast<std::size_t>(l)].push_back({col, row});
  return p;
}

// Whether cells fit a piece of furniture: at most max_extent long and max_area in hull.
bool furniture_sized(const std::vector<cv::Point>& cells, double resolution, double max_extent,
                     double max_area) {
  std::vector<cv::Point> hull;
  cv::convexHull(cells, hull);
  const cv::RotatedRect box = cv::minAreaRect(cells);
  const double extent = (std::max(box.size.width, box.size.height) + 1) * resolution;
  return extent <= max_extent && cv::contourArea(hull) * resolution * resolution <= max_area;
}

// Whether most of the cells face floor (a 4-neighbour of each is floor): a cabinet's front faces
// the room; a door's jamb faces the doorway, and a wall's end its own inside.
bool faces_floor(const SemanticGrid& grid, const std::vector<cv::Point>& cells) {
  std::size_t facing = 0;
  for (const cv::Point& c : cells) {
    for (const cv::Point d :
         {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
      const cv::Point n = c + d;
      if (seen_as(grid, {n.x, n.y}, SemanticClass::floor)) {
        ++facing;
        break;
      }
    }
  }
  return 2 * facing >= cells.size();
}

// What a pocket touches (4-neighbours): the wall pieces (labels of `wall_labels`), and whether a
// door.
struct Surroundings {
  std::set<int> walls;
  bool door = false;
};

Surroundings surroundings(const SemanticGrid& grid, const cv::Mat& wall_labels,
                          const std::vector<cv::Point>& cells) {
  Surroundings around;
  for (const cv::Point& c : cells) {
    for (const cv::Point d :
         {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
      const cv::Point n = c + d;
      if (!grid.contains({n.x, n.y})) continue;
      if (const int w = wall_labels.at<int>(n.y, n.x); w > 0) around.walls.insert(w);
      around.door |= grid.classes(n.x, n.y) == SemanticClass::door;
    }
  }
  return around;
}

}  // namespace

int fronts_against_walls(SemanticGrid& grid, double max_extent, double max_area,
                         int min_depth_cells, int max_depth_cells, float weight,
                         Image<std::uint8_t>& furniture) {
  cv::Mat wall_mask(grid.height(), grid.width(), CV_8U);
  for (int row = 0; row < grid.height(); ++row)
    for (int col = 0; col < grid.width(); ++col)
      wall_mask.at<std::uint8_t>(row, col) = is_wall(grid, col, row) ? 255 : 0;
  const Pieces walls = pieces_of(wall_mask);
  const Pieces pockets = pieces_of(pockets_between_walls(grid, min_depth_cells, max_depth_cells));
  // Wall pieces that may be a front (furniture sized, facing the room) and those that are walls
  // for certain (longer than furniture).
  std::vector<bool> front_like(walls.cells.size()), long_wall(walls.cells.size());
  for (std::size_t w = 1; w < walls.cells.size(); ++w) {
    const bool sized = furniture_sized(walls.cells[w], grid.resolution, max_extent, max_area);
    front_like[w] = sized && faces_floor(grid, walls.cells[w]);
    long_wall[w] = !sized;
  }
  int fronts = 0;
  std::vector<cv::Point> to_furniture;
  for (std::size_t p = 1; p < pockets.cells.size(); ++p) {
    if (!furniture_sized(pockets.cells[p], grid.resolution, max_extent, max_area)) continue;
    const Surroundings around = surroundings(grid, walls.labels, pockets.cells[p]);
    if (around.door) continue;  // a wall's inside behind a door leaf, not behind furniture
    const std::set<int>& beside = around.walls;
    const bool front =
        std::any_of(beside.begin(), beside.end(), [&](int w) { return front_like[w]; });
    const bool backed =
        std::any_of(beside.begin(), beside.end(), [&](int w) { return long_wall[w]; });
    if (!front || !backed) continue;
    ++fronts;
    to_furniture.insert(to_furniture.end(), pockets.cells[p].begin(), pockets.cells[p].end());
    for (const int w : beside)
      if (front_like[w])
        to_furniture.insert(to_furniture.end(), walls.cells[w].begin(), walls.cells[w].end());
  }
  for (const cv::Point& c : to_furniture) {
    grid.classes(c.x, c.y) = SemanticClass::furniture;
    grid.weight(c.x, c.y) = weight;
    furniture(c.x, c.y) = 1;
  }
  return fronts;
}

}  // namespace kartograf::semantic::detail
