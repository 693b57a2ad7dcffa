#include "kartograf/rooms/voronoi_merging.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/rooms/room_segmentation.hpp"

namespace kartograf::rooms {

namespace {

constexpr int kWall = 0;

struct Cell {
  int id = 0;
  long cells = 0;
  float max_clearance = 0;    // cells: half the widest free space in the cell
  std::map<int, int> border;  // neighbour label (kWall: wall) -> touching cells outside

  double perimeter() const {
    double sum = 0;
    for (const auto& [id, n] : border) sum += n;
    return sum;
  }
  double share(int other) const {
    const auto it = border.find(other);
    const double p = perimeter();
    return it == border.end() || p <= 0 ? 0.0 : it->second / p;
  }
  double wall() const { return share(kWall); }
  int neighbours() const { return static_cast<int>(border.size()) - (border.count(kWall) ? 1 : 0); }
  // The neighbouring cell sharing the most border (kWall if none; ties: the larger label, as the
  // reference's inverted map keeps the last one).
  int largest_neighbour() const {
    int best = kWall, best_n = -1;
    for (const auto& [id, n] : border) {
      if (id != kWall && n >= best_n) best = id, best_n = n;
    }
    return best;
  }
  // Share of the perimeter held by the `count` largest neighbours, plus the wall if it ranks
  // among them (the reference's getPerimeterRatioOfXLargestRooms).
  double largest_shares(int count) const {
    std::vector<std::pair<int, int>> by_length;
    for (const auto& [id, n] : border) by_length.emplace_back(n, id);
    std::sort(by_length.begin(), by_length.end(), std::greater<>());
    double sum = 0;
    int counted = 0;
    for (const auto& [n, id] : by_length) {
      if (counted >= count) break;
      sum += n;
      if (id != kWall) ++counted;
    }
    const double p = perimeter();
    return p > 0 ? sum / p : 0.0;
  }
};

std::vector<Cell> measure_cells(const LabelImage& labels, int count,
                                const Image<float>& clearance) {
  std::vector<Cell> cells(static_cast<std::size_t>(count) + 1);
  for (int id = 0; id <= count; ++id) cells[static_cast<std::size_t>(id)].id = id;
  const int width = labels.width(), height = labels.height();
  const auto label_at = [&](int x, int y) {
    return (x < 0 || y < 0 || x >= width || y >= height) ? 0 : static_cast<int>(labels(x, y));
  };
  // Every position (the map and a ring outside it) adds one to the border of each distinct cell
  // among its 8-neighbours that it does not belong to.
  for (int y = -1; y <= height; ++y) {
    for (int x = -1; x <= width; ++x) {
      const int own = label_at(x, y);
      if (own) {
        Cell& c = cells[static_cast<std::size_t>(own)];
        ++c.cells;
        c.max_clearance = std::max(c.max_clearance, clearance(x, y));
      }
      int seen[8];
      int n_seen = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int l = label_at(x + dx, y + dy);
          if (l == 0 || l == own || std::find(seen, seen + n_seen, l) != seen + n_seen) continue;
          seen[n_seen++] = l;
          ++cells[static_cast<std::size_t>(l)].border[own];
        }
      }
    }
  }
  return cells;
}

class Merger {
 public:
  Merger(std::vector<Cell> cells, double cell_area) : cell_area_(cell_area) {
    target_.resize(cells.size());
    std::iota(target_.begin(), target_.end(), 0);
    for (Cell& c : cells) {
      if (c.id != 0 && c.cells > 0) alive_.push_back(std::move(c));
    }
    sort();
  }

  // Runs `wants` (which returns the label to merge into, or kWall for none) over the cells,
  // smallest first, starting again after each merge.
  void run(const std::function<int(const Cell&)>& wants) {
    for (std::size_t i = 0; i < alive_.size();) {
      const int into = wants(alive_[i]);
      if (into != kWall && index_of(into) < alive_.size()) {
        merge(i, index_of(into));
        i = 0;
      } else {
        ++i;
      }
    }
  }

  const Cell* find(int id) const {
    const std::size_t i = index_of(id);
    return i < alive_.size() ? &alive_[i] : nullptr;
  }
  double area_m2(const Cell& c) const { return c.cells * cell_area_; }

  // Final label of every original label.
  std::vector<int> labels() const {
    std::vector<int> out(target_.size());
    for (std::size_t l = 0; l < target_.size(); ++l) {
      int t = static_cast<int>(l);
      while (target_[static_cast<std::size_t>(t)] != t) t = target_[static_cast<std::size_t>(t)];
      out[l] = t;
    }
    return out;
  }

 private:
  std::size_t index_of(int id) const {
    for (std::size_t i = 0; i < alive_.size(); ++i) {
      if (alive_[i].id == id) return i;
    }
    return alive_.size();
  }

  void sort() {
    std::stable_sort(alive_.begin(), alive_.end(),
                     [](const Cell& a, const Cell& b) { return a.cells < b.cells; });
  }

  void merge(std::size_t from, std::size_t into) {
    Cell& source = alive_[from];
    Cell& sink = alive_[into];
    const int gone = source.id, kept = sink.id;
    sink.cells += source.cells;
    sink.max_clearance = std::max(sink.max_clearance, source.max_clearance);
    for (const auto& [id, n] : source.border) {
      if (id != kept) sink.border[id] += n;
    }
    sink.border.erase(gone);
    target_[static_cast<std::size_t>(gone)] = kept;
    alive_.erase(alive_.begin() + static_cast<std::ptrdiff_t>(from));
    for (Cell& c : alive_) {
      if (c.id == kept) continue;
      const auto it = c.border.find(gone);
      if (it == c.border.end()) continue;
      c.border[kept] += it->second;
      c.border.erase(gone);
    }
    sort();
  }

  double cell_area_;
  std::vector<Cell> alive_;
  std::vector<int> target_;
};

}  // namespace

void merge_voronoi_cells(LabelImage& cells, const OccupancyGrid& map, const CellMergeParams& p) {
  require(cells.width() == map.width() && cells.height() == map.height(),
          "merge_voronoi_cells: the label image differs from the map in size");
  require(std::isfinite(p.open_border_ratio) && p.open_border_ratio >= 0,
          "merge_voronoi_cells: open_border_ratio must be >= 0");
  require(std::isfinite(p.open_end_ratio) && p.open_end_ratio >= 0,
          "merge_voronoi_cells: open_end_ratio must be >= 0");
  require(std::isfinite(p.doorway_ratio) && p.doorway_ratio >= 0,
          "merge_voronoi_cells: doorway_ratio must be >= 0");
  int count = 0;
  for (const Label l : cells.pixels()) count = std::max(count, static_cast<int>(l));
  if (count == 0) return;
  Merger m(measure_cells(cells, count, clearance(map)), map.resolution * map.resolution);
  // Cell c's border with neighbour t is narrower than the widest free space of both: a doorway.
  const auto doorway_between = [&](const Cell& c, const Cell& t, int border) {
    return border < p.doorway_ratio * 2.0 * std::min(c.max_clearance, t.max_clearance);
  };

  m.run([&](const Cell& c) {  // 1. small, one neighbour, not closed off by walls
    return m.area_m2(c) < p.max_area_m2 && c.neighbours() == 1 &&
                   c.wall() <= p.one_neighbour_max_wall
               ? c.largest_neighbour()
               : kWall;
  });
  m.run([&](const Cell& c) {  // 2. very small
    const int n = c.largest_neighbour();
    if (m.area_m2(c) >= p.small_area_m2 || n == kWall || c.share(n) <= p.small_min_shared)
      return kWall;
    const Cell* t = m.find(n);
    return t && t->wall() <= p.small_target_max_wall ? n : kWall;
  });
  m.run([&](const Cell& c) {  // 3. two parts of one room
    const int n = c.largest_neighbour();
    if (n == kWall || !(c.neighbours() == 1 || c.largest_shares(1) > p.part_dominant_share) ||
        c.wall() <= p.part_min_wall || c.share(n) <= p.part_min_shared)
      return kWall;
    const Cell* t = m.find(n);
    if (!t || (t->neighbours() > p.part_target_max_neighbours &&
               t->largest_shares(2) < p.part_target_two_largest))
      return kWall;
    return n;
  });
  m.run([&](const Cell& c) {  // 3b. pieces of one corridor or hall
    if (p.open_border_ratio <= 0) return kWall;
    for (const auto& [id, n] : c.border) {
      const Cell* t = id == kWall ? nullptr : m.find(id);
      if (!t) continue;
      if (n >= p.open_border_ratio * 2.0 * std::max(c.max_clearance, t->max_clearance) ||
          n >= p.open_end_ratio * 2.0 * std::min(c.max_clearance, t->max_clearance))
        return id;
    }
    return kWall;
  });
  m.run([&](const Cell& c) {  // 4. sharing most of the border
    std::vector<std::pair<int, int>> by_length;
    for (const auto& [id, n] : c.border) {
      if (id != kWall) by_length.emplace_back(n, id);
    }
    std::sort(by_length.begin(), by_length.end(), std::greater<>());
    const double wall = c.wall();
    for (const auto& [n, id] : by_length) {
      const double r = c.share(id);
      if (!(r > p.shared_min || (r > p.shared_min_low && wall > 1 - 2 * r - 0.05 && wall < 1 - r)))
        continue;
      const Cell* t = m.find(id);
      if (t && t->share(c.id) > p.shared_min_of_neighbour && !doorway_between(c, *t, n)) return id;
    }
    return kWall;
  });
  m.run([&](const Cell& c) {  // 5. mostly surrounded by one neighbour
    const int n = c.largest_neighbour();
    return n != kWall && c.share(n) > p.dominant_neighbour ? n : kWall;
  });

  const std::vector<int> final_label = m.labels();
  for (Label& l : cells.pixels()) l = static_cast<Label>(final_label[l]);
}

}  // namespace kartograf::rooms
