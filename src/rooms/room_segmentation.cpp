#include "kartograf/rooms/room_segmentation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>

#include <opencv2/imgproc.hpp>

#include "kartograf/core/connected_components.hpp"
#include "kartograf/core/error.hpp"
#include "rooms/grid_neighbours.hpp"

namespace kartograf::rooms {

void AreaLimits::check(const std::string& what) const {
  require(std::isfinite(min_m2) && std::isfinite(max_m2) && min_m2 >= 0 && max_m2 > min_m2,
          what + ": room area limits must satisfy 0 <= min < max, got " + std::to_string(min_m2) +
              " .. " + std::to_string(max_m2));
}

void check_map(const OccupancyGrid& map, const std::string& what) {
  require(map.width() > 0 && map.height() > 0, what + ": the map is empty");
  require(std::isfinite(map.resolution) && map.resolution > 0,
          what + ": the resolution must be > 0, got " + std::to_string(map.resolution));
  require(std::any_of(map.cells.pixels().begin(), map.cells.pixels().end(),
                      [](CellState c) { return c == CellState::free; }),
          what + ": the map has no free cell");
}

namespace {

// Priority flood of the unlabelled free cells from the labelled ones, level by level from the
// highest (bucket_of: a cell's level, 0 .. top); within a level, breadth first. A cell takes the
// label of the cell that reaches it first; one above the current level is flooded at it.
template <class BucketOf>
void flood_rooms(LabelImage& rooms, const OccupancyGrid& map, int top, BucketOf bucket_of) {
  const int width = map.width(), height = map.height();
  std::vector<std::vector<std::uint32_t>> buckets(static_cast<std::size_t>(top) + 1);
  const CellState* cell = map.cells.data();
  Label* label = rooms.data();
  for (std::size_t i = 0; i < rooms.size(); ++i) {
    if (label[i] != 0)
      buckets[static_cast<std::size_t>(bucket_of(i))].push_back(static_cast<std::uint32_t>(i));
  }
  for (int b = top; b >= 0; --b) {
    std::vector<std::uint32_t>& queue = buckets[static_cast<std::size_t>(b)];
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::uint32_t i = queue[head];
      detail::for_each_neighbour8(i, width, height, [&](std::uint32_t j) {
        if (label[j] != 0 || cell[j] != CellState::free) return;
        label[j] = label[i];
        buckets[static_cast<std::size_t>(std::min(b, bucket_of(j)))].push_back(j);
      });
    }
    std::vector<std::uint32_t>().swap(queue);
  }
}

}  // namespace

void grow_rooms(LabelImage& rooms, const OccupancyGrid& map) {
  require(rooms.width() == map.width() && rooms.height() == map.height(),
          "grow_rooms: the label image differs from the map in size");
  flood_rooms(rooms, map, 0, [](std::size_t) { return 0; });
}

std::size_t extend_rooms_over_enclosed(LabelImage& rooms, const Image<std::uint8_t>& fillable) {
  const int width = rooms.width(), height = rooms.height();
  require(fillable.width() == width && fillable.height() == height,
          "extend_rooms_over_enclosed: the fillable mask differs from the label image in size");
  const auto open = [&](int x, int y) { return fillable(x, y) && rooms(x, y) == 0; };
  constexpr std::array<std::array<int, 2>, 4> kSteps = {{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
  // Mark the open components that reach the border: the outside.
  Image<std::uint8_t> outside(width, height, 0);
  std::vector<Eigen::Vector2i> queue;
  const auto push_outside = [&](int x, int y) {
    if (open(x, y) && !outside(x, y)) outside(x, y) = 1, queue.emplace_back(x, y);
  };
  for (int x = 0; x < width; ++x) push_outside(x, 0), push_outside(x, height - 1);
  for (int y = 0; y < height; ++y) push_outside(0, y), push_outside(width - 1, y);
  for (std::size_t k = 0; k < queue.size(); ++k) {
    for (const auto& [dx, dy] : kSteps) {
      const int x = queue[k].x() + dx, y = queue[k].y() + dy;
      if (x >= 0 && y >= 0 && x < width && y < height) push_outside(x, y);
    }
  }
  // Breadth first from every labelled cell into the enclosed open cells.
  queue.clear();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (rooms(x, y)) queue.emplace_back(x, y);
    }
  }
  std::size_t taken = 0;
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const Label room = rooms(queue[k].x(), queue[k].y());
    for (const auto& [dx, dy] : kSteps) {
      const int x = queue[k].x() + dx, y = queue[k].y() + dy;
      if (x < 0 || y < 0 || x >= width || y >= height || !open(x, y) || outside(x, y)) continue;
      rooms(x, y) = room;
      queue.emplace_back(x, y);
      ++taken;
    }
  }
  return taken;
}

std::size_t free_unseen_islands(OccupancyGrid& map, double max_area_m2) {
  require(std::isfinite(max_area_m2) && max_area_m2 >= 0,
          "free_unseen_islands: the largest island must be a finite area >= 0 m^2");
  const int width = map.width(), height = map.height();
  Image<std::uint8_t> unknown(width, height, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) unknown(x, y) = map.cells(x, y) == CellState::unknown;
  const LabelImage islands = label_connected_components(unknown, {Connectivity::eight, 1});
  // Per island: its cells, and whether it reaches the border (then it is the outside).
  std::vector<std::size_t> cells(1, 0);
  std::vector<std::uint8_t> border(1, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Label island = islands(x, y);
      if (island == 0) continue;
      if (island >= cells.size()) cells.resize(island + 1, 0), border.resize(island + 1, 0);
      ++cells[island];
      border[island] |= x == 0 || y == 0 || x == width - 1 || y == height - 1;
    }
  }
  const double cell_area = map.resolution * map.resolution;
  std::size_t freed = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Label island = islands(x, y);
      if (island == 0 || border[island] ||
          static_cast<double>(cells[island]) * cell_area > max_area_m2)
        continue;
      map.cells(x, y) = CellState::free;
      ++freed;
    }
  }
  return freed;
}

int merge_room_fragments(LabelImage& rooms, double cell_area_m2, double max_area_m2) {
  require(cell_area_m2 > 0 && max_area_m2 >= 0,
          "merge_room_fragments: cell area must be positive and the area limit not negative");
  const int width = rooms.width(), height = rooms.height();
  int merged = 0;
  for (;;) {
    std::map<Label, std::size_t> cells;
    for (const Label l : rooms.pixels()) {
      if (l) ++cells[l];
    }
    // Borders between 4-neighbouring cells of two rooms.
    std::map<std::pair<Label, Label>, int> border;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const Label a = rooms(x, y);
        if (!a) continue;
        for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
          if (nx >= width || ny >= height) continue;
          const Label b = rooms(nx, ny);
          if (b && b != a) ++border[{std::min(a, b), std::max(a, b)}];
        }
      }
    }
    // The smallest fragment, and its neighbour with the longest border.
    Label fragment = 0, into = 0;
    std::size_t fragment_cells = 0;
    int longest = 0;
    for (const auto& [pair, length] : border) {
      for (const auto& [small, other] : {pair, std::pair{pair.second, pair.first}}) {
        const std::size_t n = cells[small];
        if (static_cast<double>(n) * cell_area_m2 >= max_area_m2) continue;
        if (!fragment || n < fragment_cells || (small == fragment && length > longest)) {
          fragment = small, fragment_cells = n, into = other, longest = length;
        }
      }
    }
    if (!fragment) return merged;
    for (Label& l : rooms.pixels()) {
      if (l == fragment) l = into;
    }
    ++merged;
  }
}

Image<float> clearance(const OccupancyGrid& map) {
  const int width = map.width(), height = map.height();
  // A one-cell frame of obstacles so that the map's edge counts as not free.
  cv::Mat free(height + 2, width + 2, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < height; ++y) {
    std::uint8_t* row = free.ptr<std::uint8_t>(y + 1) + 1;
    for (int x = 0; x < width; ++x) row[x] = map.cells(x, y) == CellState::free ? 255 : 0;
  }
  cv::Mat distance;
  cv::distanceTransform(free, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  Image<float> result(width, height);
  for (int y = 0; y < height; ++y) {
    const float* row = distance.ptr<float>(y + 1) + 1;
    std::copy(row, row + width, &result(0, y));
  }
  return result;
}

void grow_rooms_by_clearance(LabelImage& rooms, const OccupancyGrid& map,
                             const Image<float>& clearance) {
  const int width = map.width(), height = map.height();
  require(rooms.width() == width && rooms.height() == height && clearance.width() == width &&
              clearance.height() == height,
          "grow_rooms_by_clearance: the label and clearance images differ from the map in size");
  // A bucket per quarter cell of clearance: O(cells).
  const auto bucket_of = [&](std::size_t i) {
    return static_cast<int>(std::max(0.0f, clearance.data()[i]) * 4.0f);
  };
  int top = 0;
  for (std::size_t i = 0; i < rooms.size(); ++i) top = std::max(top, bucket_of(i));
  flood_rooms(rooms, map, top, bucket_of);
}

RoomSegmentation finish_segmentation(LabelImage rooms, const OccupancyGrid& map, std::string method,
                                     std::chrono::steady_clock::time_point start) {
  require(rooms.width() == map.width() && rooms.height() == map.height(),
          "finish_segmentation: the label image differs from the map in size");
  for (std::size_t i = 0; i < rooms.size(); ++i) {
    if (map.cells.data()[i] != CellState::free) rooms.data()[i] = 0;
  }
  RoomSegmentation result;
  result.records = describe_rooms(rooms, map);
  result.rooms = std::move(rooms);
  result.method = std::move(method);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<RoomRecord> describe_rooms(LabelImage& rooms, const OccupancyGrid& map) {
  const int width = map.width(), height = map.height();
  require(rooms.width() == width && rooms.height() == height,
          "describe_rooms: the label image differs from the map in size");
  // Renumber the labels in use to 1..n.
  std::vector<Label> renumber(65536, 0);
  for (const Label l : rooms.pixels()) renumber[l] = l ? 1 : 0;
  Label next = 0;
  for (std::size_t l = 1; l < renumber.size(); ++l) {
    if (renumber[l]) renumber[l] = ++next;
  }
  for (Label& l : rooms.pixels()) l = renumber[l];

  std::vector<RoomRecord> records(next);
  std::vector<Eigen::Vector2d> sums(next, Eigen::Vector2d::Zero());
  for (Label id = 1; id <= next; ++id) {
    records[id - 1].id = id;
    records[id - 1].min_cell = Eigen::Vector2i(width, height);
    records[id - 1].max_cell = Eigen::Vector2i(-1, -1);
  }
  // Border cells of each pair of touching rooms, to find the doorway segments.
  std::map<std::pair<Label, Label>, std::vector<Eigen::Vector2i>> borders;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Label l = rooms(x, y);
      if (l == 0) continue;
      RoomRecord& r = records[l - 1];
      ++r.cells;
      sums[l - 1] += Eigen::Vector2d(x, y);
      r.min_cell = r.min_cell.cwiseMin(Eigen::Vector2i(x, y));
      r.max_cell = r.max_cell.cwiseMax(Eigen::Vector2i(x, y));
      Label last = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const Label o = rooms(nx, ny);
          if (o == 0 || o == l || o == last) continue;
          last = o;
          auto& cells = borders[{l, o}];
          if (cells.empty() || cells.back() != Eigen::Vector2i(x, y)) cells.emplace_back(x, y);
        }
      }
    }
  }
  const double area = map.resolution * map.resolution;
  for (RoomRecord& r : records) {
    r.area_m2 = r.cells * area;
    const Eigen::Vector2d c = sums[r.id - 1] / std::max(1, r.cells);
    r.centroid =
        map.cell_center(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())));
    const Eigen::Vector2d a = map.cell_center(r.min_cell.x(), r.max_cell.y());
    const Eigen::Vector2d b = map.cell_center(r.max_cell.x(), r.min_cell.y());
    r.min_corner = a.cwiseMin(b);
    r.max_corner = a.cwiseMax(b);
  }
  for (const auto& [pair, cells] : borders) {
    RoomRecord& r = records[pair.first - 1];
    // The two border cells farthest apart (a doorway is a short straight border: its extreme
    // cells; long borders have many cells and the pair still spans them).
    std::size_t best_a = 0, best_b = 0;
    long long best = -1;
    const std::size_t step = std::max<std::size_t>(1, cells.size() / 200);  // bounded work
    for (std::size_t i = 0; i < cells.size(); i += step) {
      for (std::size_t j = i; j < cells.size(); j += step) {
        const long long d = (cells[i] - cells[j]).cast<long long>().squaredNorm();
        if (d > best) best = d, best_a = i, best_b = j;
      }
    }
    Doorway door;
    door.other = pair.second;
    door.cells = static_cast<int>(cells.size());
    door.from = map.cell_center(cells[best_a].x(), cells[best_a].y());
    door.to = map.cell_center(cells[best_b].x(), cells[best_b].y());
    door.width_m = (door.to - door.from).norm() + map.resolution;
    r.neighbours.push_back(pair.second);
    r.doorways.push_back(door);
  }
  return records;
}

}  // namespace kartograf::rooms
