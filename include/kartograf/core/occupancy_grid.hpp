#pragma once
// A 2-D occupancy grid in the ROS map_server convention: row 0 is the top of the picture (the
// largest y), and `origin` is the map-frame pose (x, y, yaw) of the lower-left corner of the
// lower-left cell.
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "kartograf/core/image.hpp"

namespace kartograf {

enum class CellState : std::uint8_t { unknown = 0, free = 1, occupied = 2 };

struct OccupancyGrid {
  Image<CellState> cells;
  double resolution = 0.05;  // metres per cell
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // x [m], y [m], yaw [rad]

  int width() const { return cells.width(); }
  int height() const { return cells.height(); }

  // Map-frame position of a cell's centre (yaw applied about the origin).
  Eigen::Vector2d cell_center(int col, int row) const {
    const Eigen::Vector2d local((col + 0.5) * resolution, (height() - row - 0.5) * resolution);
    return origin.head<2>() + rotation() * local;
  }

  // The cell containing a map-frame point, possibly outside the grid (check with contains()).
  Eigen::Vector2i cell_of(const Eigen::Vector2d& point) const {
    const Eigen::Vector2d local = rotation().transpose() * (point - origin.head<2>());
    const int col = static_cast<int>(std::floor(local.x() / resolution));
    const int row = height() - 1 - static_cast<int>(std::floor(local.y() / resolution));
    return {col, row};
  }

  bool contains(const Eigen::Vector2i& cell) const {
    return cell.x() >= 0 && cell.y() >= 0 && cell.x() < width() && cell.y() < height();
  }

 private:
  Eigen::Matrix2d rotation() const {
    const double c = std::cos(origin.z()), s = std::sin(origin.z());
    Eigen::Matrix2d r;
    r << c, -s, s, c;
    return r;
  }
};

}  // namespace kartograf
