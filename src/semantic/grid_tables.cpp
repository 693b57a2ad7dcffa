#include "semantic/grid_tables.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "kartograf/core/connected_components.hpp"
#include "semantic/grid_cells.hpp"

namespace kartograf::semantic::detail {
namespace {

// Sides at right angles within 8 degrees: |cos| of the angle between them.
constexpr double kMaxCosine = 0.139;
// How far from the rectangle's fourth corner its leg may stand [cells].
constexpr double kFourthLegReach = 2.5;
// A leg's reach around its centre where it is not seen [cells].
constexpr double kLegHalfWidth = 0.5;
// Rays over a solid top: the inner cells crossed at most this share of the ring's rate.
constexpr double kSolidTopShare = 0.2;
// The share of the inner cells that must be crossed that rarely.
constexpr double kMinBlockedShare = 0.8;
// The ring around a top whose rays it is judged against [cells out], and the inner cells' margin.
constexpr double kRingFrom = 2, kRingTo = 4, kInnerMargin = 1;
constexpr double kSlabStep = 0.02;  // m
// Where a table's top may be, from its legs' median top [m]: their points reach its underside.
constexpr double kBelowLegTops = 0.04, kAboveLegTops = 0.03;

// A rectangle as an origin, two unit axes and its extents along them.
struct Frame {
  Eigen::Vector2d origin, u, v;
  double u_length = 0, v_length = 0;

  explicit Frame(const TableTop& top)
      : origin(top[0]),
        u((top[1] - top[0]).normalized()),
        v((top[3] - top[0]).normalized()),
        u_length((top[1] - top[0]).norm()),
        v_length((top[3] - top[0]).norm()) {}

  // How far p lies outside the rectangle along its axes (negative inside) [cells].
  double outside(const Eigen::Vector2d& p) const {
    const double s = (p - origin).dot(u), t = (p - origin).dot(v);
    return std::max({-s, s - u_length, -t, t - v_length});
  }
};

// The rectangle with sides along `u` and its normal around the points.
TableTop rectangle_around(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& u) {
  const Eigen::Vector2d v(-u.y(), u.x());
  constexpr double kFar = std::numeric_limits<double>::infinity();
  double s0 = kFar, s1 = -kFar, t0 = kFar, t1 = -kFar;
  for (const Eigen::Vector2d& p : points) {
    s0 = std::min(s0, p.dot(u)), s1 = std::max(s1, p.dot(u));
    t0 = std::min(t0, p.dot(v)), t1 = std::max(t1, p.dot(v));
  }
  return {s0 * u + t0 * v, s1 * u + t0 * v, s1 * u + t1 * v, s0 * u + t1 * v};
}

struct Candidate {
  double area = 0;
  std::vector<int> legs;  // sorted
  TableTop top;
};

// The rectangle with legs a, b (the right angle's) and c at its corners, if their sides fit.
std::optional<Candidate> candidate(std::span<const TableLeg> legs,
                                   const std::vector<Eigen::Vector2d>& centres, int a, int b, int c,
                                   const LegLimits& limits) {
  const Eigen::Vector2d u = centres[a] - centres[b], v = centres[c] - centres[b];
  const double lu = u.norm(), lv = v.norm();
  if (lu < limits.min_side || lu > limits.max_side || lv < limits.min_side ||
      lv > limits.max_side || std::fabs(u.dot(v)) > kMaxCosine * lu * lv)
    return std::nullopt;
  const Eigen::Vector2d fourth = centres[a] + v;
  Candidate found;
  found.legs = {a, b, c};
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < static_cast<int>(legs.size()); ++k) {
    if (k != a && k != b && k != c && (centres[k] - fourth).norm() <= kFourthLegReach) {
      found.legs.push_back(k);
      break;
    }
  }
  if (found.legs.size() == 3) {
    for (const double ds : {-kLegHalfWidth, kLegHalfWidth})
      for (const double dt : {-kLegHalfWidth, kLegHalfWidth})
        points.push_back(fourth + ds * u / lu + dt * v / lv);
  }
  for (const int k : found.legs)
    for (const Eigen::Vector2i& cell : legs[k].cells) points.push_back(cell.cast<double>());
  found.top = rectangle_around(points, u / lu);
  const Frame frame(found.top);
  found.area = frame.u_length * frame.v_length;
  if (found.area > limits.max_area) return std::nullopt;
  std::sort(found.legs.begin(), found.legs.end());
  for (int k = 0; k < static_cast<int>(legs.size()); ++k) {
    if (!std::binary_search(found.legs.begin(), found.legs.end(), k) &&
        frame.outside(centres[k]) <= -kInnerMargin)
      return std::nullopt;
  }
  return found;
}

// Calls visit(cell, how far the cell lies outside `top` [cells]) for every cell of the top's
// bounding box grown by `reach` cells.
template <typename Visit>
void cells_around(const TableTop& top, double reach, Visit&& visit) {
  const Frame frame(top);
  Eigen::Vector2d lo = top[0], hi = top[0];
  for (const Eigen::Vector2d& corner : top) lo = lo.cwiseMin(corner), hi = hi.cwiseMax(corner);
  for (int y = static_cast<int>(std::floor(lo.y() - reach));
       y <= static_cast<int>(std::ceil(hi.y() + reach)); ++y) {
    for (int x = static_cast<int>(std::floor(lo.x() - reach));
         x <= static_cast<int>(std::ceil(hi.x() + reach)); ++x)
      visit(Eigen::Vector2i(x, y), frame.outside(Eigen::Vector2d(x, y)));
  }
}

// Whether rays passed over `top` as over a solid top: at some observable height from `low` to
// `high` above the floor, at least kMinBlockedShare of its inner cells (kInnerMargin in from its
// edges) were crossed at most kSolidTopShare as often as the cells around it (kRingFrom-kRingTo
// cells out) on average, which were crossed at least once a cell. Open floor between the legs of
// two tables is crossed like the floor around it.
bool under_solid_top(const BandFreeSpace& free_space, const TableTop& top, double low,
                     double high) {
  std::vector<Eigen::Vector2i> inner, ring;
  cells_around(top, kRingTo, [&](const Eigen::Vector2i& c, double out) {
    if (out <= -kInnerMargin) inner.push_back(c);
    if (out >= kRingFrom && out <= kRingTo) ring.push_back(c);
  });
  if (inner.empty() || ring.empty()) return false;
  for (double height = low; height <= high; height += kSlabStep) {
    if (!free_space.observable(height)) continue;
    double around = 0;
    for (const Eigen::Vector2i& c : ring) around += free_space.passes(c, height);
    around /= static_cast<double>(ring.size());
    const auto blocked = std::count_if(inner.begin(), inner.end(), [&](const Eigen::Vector2i& c) {
      return free_space.passes(c, height) <= kSolidTopShare * around;
    });
    if (around >= 1 && blocked >= kMinBlockedShare * static_cast<double>(inner.size())) return true;
  }
  return false;
}

std::vector<Eigen::Vector2i> cells_under(const TableTop& top) {
  std::vector<Eigen::Vector2i> cells;
  cells_around(top, 0, [&](const Eigen::Vector2i& c, double out) {
    if (out <= 1e-6) cells.push_back(c);
  });
  return cells;
}

}  // namespace

Eigen::Vector2d TableLeg::centre() const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2i& c : cells) sum += c.cast<double>();
  return cells.empty() ? sum : sum / static_cast<double>(cells.size());
}

std::vector<LegTable> tables_on_legs(std::span<const TableLeg> legs, const LegLimits& limits) {
  std::vector<Eigen::Vector2d> centres;
  for (const TableLeg& leg : legs) centres.push_back(leg.centre());
  const int n = static_cast<int>(legs.size());
  std::vector<Candidate> candidates;
  for (int b = 0; b < n; ++b) {
    for (int a = 0; a < n; ++a) {
      if (a == b || (centres[a] - centres[b]).norm() > limits.max_side) continue;
      for (int c = a + 1; c < n; ++c) {
        if (c == b) continue;
        if (std::optional<Candidate> found = candidate(legs, centres, a, b, c, limits))
          candidates.push_back(std::move(*found));
      }
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) {
                     if (x.legs.size() != y.legs.size()) return x.legs.size() > y.legs.size();
                     return x.area < y.area;
                   });
  std::set<int> used;
  std::vector<LegTable> tables;
  for (const Candidate& found : candidates) {
    if (std::any_of(found.legs.begin(), found.legs.end(), [&](int k) { return used.count(k); }))
      continue;
    used.insert(found.legs.begin(), found.legs.end());
    tables.push_back({found.top, found.legs});
  }
  return tables;
}

std::vector<LegTable> fill_tables_on_legs(SemanticGrid& grid, std::span<const TableLeg> legs,
                                          const LegLimits& limits, const BandFreeSpace& free_space,
                                          float weight, Image<std::uint8_t>& furniture) {
  std::vector<LegTable> tables;
  for (const LegTable& table : tables_on_legs(legs, limits)) {
    std::vector<double> tops;
    for (const int k : table.legs) tops.push_back(legs[k].top);
    std::nth_element(tops.begin(), tops.begin() + tops.size() / 2, tops.end());
    const double middle = tops[tops.size() / 2];
    const bool solid =
        under_solid_top(free_space, table.top, middle - kBelowLegTops, middle + kAboveLegTops);
    if (!solid) continue;
    std::vector<Eigen::Vector2i> filled = cells_under(table.top);
    std::erase_if(
        filled, [&](const Eigen::Vector2i& c) { return !seen_as(grid, c, SemanticClass::floor); });
    set_class(grid, filled, SemanticClass::furniture, weight);
    for (const Eigen::Vector2i& c : filled) furniture(c.x(), c.y()) = 1;
    tables.push_back(table);
  }
  return tables;
}

int trim_fills_around_tables(SemanticGrid& grid, std::span<const LegTable> tables,
                             const Image<std::uint8_t>& marked, float floor_weight,
                             Image<std::uint8_t>& furniture) {
  constexpr double kTopMargin = 1;  // cells: a top overhangs its legs
  constexpr int kWallReach = 3;     // cells: a wall's face with floor this near is a front
  constexpr std::size_t kAllLegs = 4;
  std::vector<Frame> frames;  // every table's top, where the fill stays
  for (const LegTable& table : tables) frames.emplace_back(table.top);
  const auto near_a_table = [&](const Eigen::Vector2i& c) {
    return std::any_of(frames.begin(), frames.end(),
                       [&](const Frame& f) { return f.outside(c.cast<double>()) <= kTopMargin; });
  };
  const auto near_a_wall = [&](const Eigen::Vector2i& c) {
    for (int dy = -kWallReach; dy <= kWallReach; ++dy)
      for (int dx = -kWallReach; dx <= kWallReach; ++dx)
        if (seen_as(grid, c + Eigen::Vector2i(dx, dy), SemanticClass::wall)) return true;
    return false;
  };
  // The pieces of furniture (8-connected) that hold a four-legged table's cells.
  const LabelImage pieces = label_connected_components(furniture, {Connectivity::eight, 1});
  std::set<Label> at_tables;
  for (const LegTable& table : tables) {
    if (table.legs.size() != kAllLegs) continue;
    for (const Eigen::Vector2i& c : cells_under(table.top))
      if (grid.contains(c) && pieces(c.x(), c.y())) at_tables.insert(pieces(c.x(), c.y()));
  }
  std::vector<Eigen::Vector2i> trimmed;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i c(col, row);
      if (at_tables.count(pieces(col, row)) && !marked(col, row) && !near_a_table(c) &&
          !near_a_wall(c))
        trimmed.push_back(c);
    }
  }
  set_class(grid, trimmed, SemanticClass::floor, floor_weight);
  for (const Eigen::Vector2i& c : trimmed) furniture(c.x(), c.y()) = 0;
  return static_cast<int>(trimmed.size());
}

}  // namespace kartograf::semantic::detail
