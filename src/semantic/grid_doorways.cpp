#include "semantic/grid_doorways.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "semantic/grid_band_points.hpp"
#include "semantic/grid_cells.hpp"
#include "semantic/quantile.hpp"

namespace kartograf::semantic::detail {
namespace {

// How far beyond an opening's ends, and how far either side of its line, its jambs are looked
// for [m] (walls are at most kMaxWallThickness thick).
constexpr double kJambDepth = 0.15;
constexpr double kMaxWallThickness = 0.3;
// Thinner than any wall (a stud partition is 7 cm or more); not a cell count, since a 10 cm wall
// measures 2 cells give or take a millimetre.
constexpr double kMinWallThickness = 0.05;

// An opening found between two collinear wall pieces: its two ends on the wall line.
struct WallGap {
  Eigen::Vector2d a, b;
  int merged = 1;
};

// A doorway's opening in the frame of its gap (centre; along the wall; across it) [m].
struct Opening {
  double along_min, along_max, across_min, across_max;
  bool contains(double along, double across) const {
    return along >= along_min && along <= along_max && across >= across_min && across <= across_max;
  }
};

// Distance from the opening's centre line to one jamb's reveal, from the |along| of that jamb's
// points: the reveal (a surface across the wall) piles its points up at one distance, the
// faces spread theirs evenly beyond it. The densest centimetre within 10 cm of the nearest points
// (a low quantile: flying pixels), refined by the mean around it.
double reveal_distance(std::vector<double>& along) {
  for (double& a : along) a = std::fabs(a);
  const double nearest = detail::quantile(along, 0.02);
  constexpr int kBins = 10;  // 1 cm each
  std::array<int, kBins> counts{};
  for (const double a : along) {
    const int bin = static_cast<int>((a - nearest) / 0.01);
    if (bin >= 0 && bin < kBins) ++counts[bin];
  }
  const auto peak = std::max_element(counts.begin(), counts.end()) - counts.begin();
  const double centre = nearest + 0.01 * (static_cast<double>(peak) + 0.5);
  double sum = 0;
  int n = 0;
  for (const double a : along) {
    if (std::fabs(a - centre) <= 0.015) sum += a, ++n;
  }
  return sum / n;
}

// The opening between two jambs, measured on their wall points (finer than the cells, which
// straddle the faces): the reveals bound it along the wall, the faces (and the reveals, which
// span the wall) across it. Empty when either jamb has too few points or the result is no
// plausible doorway.
std::optional<Opening> measure_jambs(const SemanticGrid& grid, const BandPointIndex& walls,
                                     const Eigen::Vector2d& centre, const Eigen::Vector2d& u,
                                     double width, const SemanticGridParams& options) {
  constexpr double kInside = 0.1;  // jamb points may lie this far inside the cells' opening
  constexpr std::size_t kMinPoints = 10;
  constexpr double kRevealMargin = 0.03;  // face points lie this far beyond the reveals
  const Eigen::Vector2d n(-u.y(), u.x());
  std::vector<double> side_a, side_b, alongs, offsets;
  const double res = grid.resolution;
  const Eigen::Vector2i c0 = grid.cell_of(centre);
  const int reach =
      static_cast<int>(std::ceil((0.5 * width + kJambDepth + kMaxWallThickness) / res)) + 1;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const Eigen::Vector2i c = c0 + Eigen::Vector2i(dx, dy);
      if (!grid.contains(c)) continue;
      for (const Eigen::Vector2d& p : walls.in_cell(c)) {
        const double along = u.dot(p - centre), off = n.dot(p - centre);
        if (std::fabs(off) > kMaxWallThickness || std::fabs(along) < 0.5 * width - kInside ||
            std::fabs(along) > 0.5 * width + kJambDepth)
          continue;
        (along < 0 ? side_a : side_b).push_back(along);
        alongs.push_back(along);
        offsets.push_back(off);
      }
    }
  }
  if (side_a.size() < kMinPoints || side_b.size() < kMinPoints) return std::nullopt;
  Opening o{-reveal_distance(side_a), reveal_distance(side_b), 0, 0};
  // The faces: two means of the offsets of the points beyond the reveals (on the faces), started
  // at their extremes; the mean of a face's points is unbiased where the cells straddle it.
  std::vector<double> faces;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    const double along = alongs[i];
    if (along < o.along_min - kRevealMargin || along > o.along_max + kRevealMargin)
      faces.push_back(offsets[i]);
  }
  if (faces.size() < 2 * kMinPoints) return std::nullopt;
  double lo = detail::quantile(faces, 0.02), hi = detail::quantile(faces, 0.98);
  for (int iteration = 0; iteration < 10; ++iteration) {
    double sum_lo = 0, sum_hi = 0;
    std::size_t n_lo = 0, n_hi = 0;
    for (const double f : faces) {
      if (f - lo < hi - f)
        sum_lo += f, ++n_lo;
      else
        sum_hi += f, ++n_hi;
    }
    if (n_lo < kMinPoints || n_hi < kMinPoints) return std::nullopt;
    lo = sum_lo / n_lo, hi = sum_hi / n_hi;
  }
  o.across_min = lo, o.across_max = hi;
  // Faces more than a cell apart beyond the walls' own thickness (measured where both faces of a
  // wall were seen) are not this wall's: an open door leaf standing against it beside the jamb
  // lies beyond the reveal like a face. The doorway then keeps to the wall's rows.
  const double max_thickness =
      grid.inferred.wall_thickness
          ? std::min(kMaxWallThickness, *grid.inferred.wall_thickness + res)
          : kMaxWallThickness;
  const double measured_width = o.along_max - o.along_min;
  const bool plausible = measured_width >= 0.75 * options.min_door_width &&
                         measured_width <= 1.25 * options.max_door_width &&
                         std::fabs(measured_width - width) <= 2 * kInside &&
                         o.across_max - o.across_min >= kMinWallThickness &&
                         o.across_max - o.across_min <= max_thickness;
  if (!plausible) return std::nullopt;
  return o;
}

// The fraction of observed passable cells along a..b (2 cells in from either end); 0 where the
// line leaves the grid.
double floor_fraction(const SemanticGrid& grid, const Eigen::Vector2d& a,
                      const Eigen::Vector2d& b) {
  const double res = grid.resolution;
  const double length = (b - a).norm();
  int passable = 0, total = 0;
  for (double t = 2 * res; t <= length - 2 * res; t += 0.5 * res) {
    const Eigen::Vector2i c = grid.cell_of(a + (b - a) * (t / length));
    if (!grid.contains(c)) return 0.0;
    ++total;
    passable += grid.weight(c.x(), c.y()) > 0;
  }
  return total ? static_cast<double>(passable) / total : 0.0;
}

bool is_wall(const SemanticGrid& grid, const Eigen::Vector2d& p) {
  const Eigen::Vector2i c = grid.cell_of(p);
  return grid.contains(c) && grid.classes(c.x(), c.y()) == SemanticClass::wall;
}

// Whether there is wall at `p` or a cell either side of the line (`n`).
bool wall_at(const SemanticGrid& grid, const Eigen::Vector2d& p, const Eigen::Vector2d& n) {
  const double res = grid.resolution;
  return is_wall(grid, p) || is_wall(grid, p + res * n) || is_wall(grid, p - res * n);
}

// From one end of a wall piece (`from`, walking along `dir`; `n` across the line), walk on along
// its line: floor for a door's width, then wall again (any wall cell, within a cell of the line)
// is an opening. An obstacle (furniture) in the line ends the walk, unless wall follows it within
// two cells: then it stands against the far jamb (on seed 29 with the SLAM's poses a furniture
// cell at a jamb's corner, where the walk reached the jamb, hid a 1 m doorway) and is the
// opening's end.
std::optional<WallGap> opening_beyond_end(const SemanticGrid& grid,
                                          const SemanticGridParams& options,
                                          const Eigen::Vector2d& from, const Eigen::Vector2d& dir,
                                          const Eigen::Vector2d& n) {
  const double res = grid.resolution;
  // Leave this piece's own end (noisy, up to 0.3 m: wall cells, and notches narrower than a door
  // between them), cross the opening, meet wall again.
  double open_from = -1, hit = -1;
  for (double t = 0.5 * res; t <= 0.3 + options.max_door_width + res; t += 0.5 * res) {
    const Eigen::Vector2d p = from + t * dir;
    const Eigen::Vector2i c = grid.cell_of(p);
    if (!grid.contains(c)) break;
    const bool obstacle = grid.weight(c.x(), c.y()) == 0.0f;  // wall cells are wall_here first
    const bool wall_here =
        wall_at(grid, p, n) ||
        (obstacle && (wall_at(grid, p + res * dir, n) || wall_at(grid, p + 2 * res * dir, n)));
    if (open_from < 0) {
      if (!wall_here)
        open_from = t;
      else if (t > 0.3)
        break;
      continue;
    }
    if (wall_here) {
      const double width = t - open_from;
      if (width < options.min_door_width && t <= 0.3) {
        open_from = -1;  // a notch in the piece's ragged end, not an opening: leave it further
        continue;
      }
      if (width >= options.min_door_width && width <= options.max_door_width) hit = t;
      break;
    }
    if (obstacle) break;  // furniture or another obstacle across the opening
  }
  if (hit < 0) return std::nullopt;
  return WallGap{from + open_from * dir, from + hit * dir};
}

// Whether a wall runs across the opening's line at `end` (stepping `back` out of the opening):
// wall on both sides of the line for farther than a wall is thick. Then the "opening" crosses a
// corridor from one wall to the wall opposite (two room dividers meeting it at a T from either
// side line up across it), not a gap in one wall. A wall's face is ragged (unseen or floor cells
// where it meets a divider, a cell of offset), so most of the cells beside the line within the
// wall's first rows suffice; a wall seen end-on, a door's jamb, is wall for a thickness at most.
bool wall_across(const SemanticGrid& grid, const Eigen::Vector2d& end, const Eigen::Vector2d& back,
                 const Eigen::Vector2d& n) {
  constexpr double kBeyondThickness = 0.5;  // m: walls are thinner than this
  constexpr int kRows = 3;                  // the wall's rows looked at, from its face
  constexpr double kMostly = 0.7;
  const double res = grid.resolution;
  const Eigen::Vector2d in_wall = end + res * back;
  for (const double side : {1.0, -1.0}) {
    int wall = 0, total = 0;
    for (double t = res; t <= kBeyondThickness; t += res, ++total) {
      for (int row = 0; row < kRows; ++row) {
        if (is_wall(grid, in_wall + side * t * n + row * res * back)) {
          ++wall;
          break;
        }
      }
    }
    if (wall < kMostly * total) return false;
  }
  return true;
}

// One must be able to pass through: no obstacle across the gap's middle on either side.
bool passable_across(const SemanticGrid& grid, const SemanticGridParams& options,
                     const WallGap& gap, const Eigen::Vector2d& n) {
  const double res = grid.resolution;
  bool passable = true;
  const Eigen::Vector2d middle = 0.5 * (gap.a + gap.b);
  for (double t = -options.door_passage_depth; t <= options.door_passage_depth; t += res) {
    const Eigen::Vector2i c = grid.cell_of(middle + t * n);
    passable &= grid.contains(c) && grid.weight(c.x(), c.y()) != 0.0f;
  }
  return passable;
}

// The openings beyond both ends of every wall piece, with floor along them and passable.
std::vector<WallGap> find_wall_gaps(const SemanticGrid& grid, const SemanticGridParams& options,
                                    const std::vector<int>& wall_ids) {
  std::vector<WallGap> gaps;
  for (const int id : wall_ids) {
    const SemanticObject& wall = grid.objects[id - 1];
    const Eigen::Vector2d u = (wall.axis_end - wall.axis_start).normalized();
    const Eigen::Vector2d n(-u.y(), u.x());
    const std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, 2> ends = {
        std::pair{wall.axis_end, u}, std::pair{wall.axis_start, Eigen::Vector2d(-u)}};
    for (const auto& [from, dir] : ends) {
      const std::optional<WallGap> gap = opening_beyond_end(grid, options, from, dir, n);
      if (!gap) continue;
      if (floor_fraction(grid, gap->a, gap->b) < options.min_gap_floor_fraction) continue;
      if (wall_across(grid, gap->a, -dir, n) || wall_across(grid, gap->b, dir, n)) continue;
      if (passable_across(grid, options, *gap, n)) gaps.push_back(*gap);
    }
  }
  return gaps;
}

// Merges the gaps of the two faces of one wall (orienting each like the first): gaps less than half
// a door apart along their line and at most a wall's thickness (and a cell) across it. Their ends
// are the means of the merged gaps' ends.
std::vector<WallGap> merge_face_gaps(const std::vector<WallGap>& gaps,
                                     const SemanticGridParams& options) {
  // Merged gaps hold sums until divided below.
  std::vector<WallGap> merged;
  for (WallGap gap : gaps) {
    const Eigen::Vector2d u = (gap.b - gap.a).normalized();
    auto same = std::find_if(merged.begin(), merged.end(), [&](const WallGap& m) {
      const Eigen::Vector2d offset = 0.5 * (m.a + m.b) / m.merged - 0.5 * (gap.a + gap.b);
      const double across = std::fabs(offset.x() * u.y() - offset.y() * u.x());
      return std::fabs(offset.dot(u)) < 0.5 * options.min_door_width &&
             across <= options.max_wall_thickness + options.resolution;
    });
    if (same == merged.end()) {
      merged.push_back(gap);
      continue;
    }
    if ((same->a / same->merged - gap.a).norm() > (same->a / same->merged - gap.b).norm())
      std::swap(gap.a, gap.b);
    same->a += gap.a, same->b += gap.b, ++same->merged;
  }
  for (WallGap& gap : merged) gap.a /= gap.merged, gap.b /= gap.merged;
  return merged;
}

// The passable cells within `reach` cells of `centre` that `opening` (in the frame centre, u, n)
// contains.
std::vector<Eigen::Vector2i> opening_cells(const SemanticGrid& grid, const Opening& opening,
                                           const Eigen::Vector2d& centre, const Eigen::Vector2d& u,
                                           const Eigen::Vector2d& n, int reach) {
  std::vector<Eigen::Vector2i> cells;
  const Eigen::Vector2i c0 = grid.cell_of(centre);
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const Eigen::Vector2i c = c0 + Eigen::Vector2i(dx, dy);
      if (!grid.contains(c) || !(grid.weight(c.x(), c.y()) > 0)) continue;
      if (opening.contains(u.dot(grid.cell_center(c) - centre),
                           n.dot(grid.cell_center(c) - centre)))
        cells.push_back(c);
    }
  }
  return cells;
}

// The span across the wall line (in the frame centre, u, n) of the wall cells within 3 cells
// beyond either end of the opening and within `band` of its line: the rows the map's wall
// occupies at the jambs. Empty unless both ends have a wall cell. A doorway whose jambs cannot be
// measured (a wall seen from one side only: one face, its back filled in) takes these rows rather
// than the whole misalignment band, which put a row of door on the floor either side.
std::optional<std::pair<double, double>> wall_rows_beside(
    const SemanticGrid& grid, const Opening& opening, const Eigen::Vector2d& centre,
    const Eigen::Vector2d& u, const Eigen::Vector2d& n, double band, int reach) {
  const double depth = 3 * grid.resolution;
  std::array<double, 2> lo{1e9, 1e9}, hi{-1e9, -1e9};
  const Eigen::Vector2i c0 = grid.cell_of(centre);
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const Eigen::Vector2i c = c0 + Eigen::Vector2i(dx, dy);
      if (!grid.contains(c) || grid.classes(c.x(), c.y()) != SemanticClass::wall) continue;
      const double along = u.dot(grid.cell_center(c) - centre);
      const double across = n.dot(grid.cell_center(c) - centre);
      if (std::fabs(across) > band) continue;
      const bool side_a = along < opening.along_min && along >= opening.along_min - depth;
      const bool side_b = along > opening.along_max && along <= opening.along_max + depth;
      if (!side_a && !side_b) continue;
      const int side = side_a ? 0 : 1;
      lo[side] = std::min(lo[side], across), hi[side] = std::max(hi[side], across);
    }
  }
  if (lo[0] > hi[0] || lo[1] > hi[1]) return std::nullopt;
  return std::pair{std::min(lo[0], lo[1]), std::max(hi[0], hi[1])};
}

// A doorway is as deep as its wall is thick: about the middle found across it, the opening takes
// the thickness measured on the walls seen from both sides where its jambs were measured (their
// faces, means of noisy points, miss the depth by a row now and then), and at least that thickness
// where it took the wall's rows beside it (which the faces' placement thins where the views saw
// one face; more rows there hold an open leaf's hinge, on the side it stands).
void as_deep_as_the_walls(Opening& opening, double wall_thickness, bool jambs_measured) {
  const double middle = 0.5 * (opening.across_min + opening.across_max);
  const double half = 0.5 * wall_thickness;
  opening.across_min = jambs_measured ? middle - half : std::min(opening.across_min, middle - half);
  opening.across_max = jambs_measured ? middle + half : std::max(opening.across_max, middle + half);
}

// The doorway of one (merged) gap: its cells become door cells and a doorway object.
void add_doorway(SemanticGrid& grid, const SemanticGridParams& options, const BandPointIndex& walls,
                 const WallGap& gap, int& doorway_count, const AddObject& add_object) {
  const double res = grid.resolution;
  const Eigen::Vector2d centre = 0.5 * (gap.a + gap.b);
  // Its cells: passable cells inside the opening as its jambs measure it, else along the gap
  // in the wall's rows at its jambs, within the faces' misalignment of its line.
  const double width = (gap.b - gap.a).norm();
  const Eigen::Vector2d u = (gap.b - gap.a) / width, n(-u.y(), u.x());
  const double across = 0.5 * options.max_wall_misalignment + res;
  Opening opening{-0.5 * width, 0.5 * width, -across, across};
  const int reach = static_cast<int>(std::ceil((0.5 * width + kMaxWallThickness) / res)) + 1;
  const std::optional<Opening> measured = measure_jambs(grid, walls, centre, u, width, options);
  if (measured)
    opening = *measured;
  else if (const auto rows = wall_rows_beside(grid, opening, centre, u, n, across, reach)) {
    opening.across_min = std::max(rows->first - 0.5 * res, -across);
    opening.across_max = std::min(rows->second + 0.5 * res, across);
  }
  if (options.doors_as_deep_as_walls && grid.inferred.wall_thickness)
    as_deep_as_the_walls(opening, *grid.inferred.wall_thickness, measured.has_value());
  const Eigen::Vector2d door_centre = centre + 0.5 * (opening.along_min + opening.along_max) * u +
                                      0.5 * (opening.across_min + opening.across_max) * n;
  std::vector<Eigen::Vector2i> cells = opening_cells(grid, opening, centre, u, n, reach);
  if (cells.empty()) return;
  set_class(grid, cells, SemanticClass::door, options.weights.of(SemanticClass::door));
  SemanticObject& door = add_object(ObjectKind::doorway, SemanticClass::door,
                                    "doorway " + std::to_string(++doorway_count), std::move(cells));
  door.centre = door_centre;
  door.axis_start = centre + opening.along_min * u + (door_centre - centre).dot(n) * n;
  door.axis_end = centre + opening.along_max * u + (door_centre - centre).dot(n) * n;
  door.width = opening.along_max - opening.along_min;
}

}  // namespace

void add_gap_doorways(SemanticGrid& grid, const SemanticGridParams& options,
                      const BandPointIndex& walls, const std::vector<int>& wall_ids,
                      const AddObject& add_object) {
  int doorway_count = 0;
  for (const WallGap& gap : merge_face_gaps(find_wall_gaps(grid, options, wall_ids), options))
    add_doorway(grid, options, walls, gap, doorway_count, add_object);
}

}  // namespace kartograf::semantic::detail
