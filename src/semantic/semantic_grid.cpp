#include "kartograf/semantic/semantic_grid.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <string>

#include <Eigen/Eigenvalues>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "kartograf/core/connected_components.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kartograf/semantic/labelled_views.hpp"
#include "semantic/grid_cabinets.hpp"
#include "semantic/grid_cells.hpp"
#include "semantic/grid_doorways.hpp"
#include "semantic/grid_free_space.hpp"
#include "semantic/grid_furniture.hpp"
#include "semantic/grid_phantoms.hpp"
#include "semantic/grid_tables.hpp"
#include "semantic/grid_wall_faces.hpp"
#include "semantic/grid_walls.hpp"

namespace kartograf::semantic {
namespace {

// Wall faces must be this crisp before the lattice moves for them: exp(-pi^2 / 8), their points
// spread at most a quarter of a cell across the face (1.25 cm at 5 cm cells; a depth camera's
// noise at 3-4 m is more). A measure of the faces' own spread and not of how their offsets agree:
// that one swung across its threshold with a millimetre of the poses.
constexpr double kMinFaceCrispness = 0.29;
// Face cells of walls seen from both sides needed to measure a wall's thickness (1 m of wall).
constexpr int kMinTwoSidedWallCells = 40;
// Furniture is judged seen through this far below its top: inside a table's 2-5 cm top.
constexpr double kBelowTop = 0.015;
// ... and down to this much further: a top's thickness, whatever the noise on its highest points.
constexpr double kTopDepth = 0.04;
// Wall cells whose points start this high above the floor, and that the views saw through below
// them (to kBelowWall under their lowest point), stand on nothing: a table's edge, not a wall.
constexpr double kRaisedWall = 0.3, kBelowWall = 0.05;
// Wall cells are judged seen through this far above their highest point (the noise on it), in a
// slab kTopDepth thick.
constexpr double kAboveWall = 0.05;
// Above the heights the views observe, few rays pass and each counts: a slab is judged seen
// through there when this many crossed it (twice the two asked below the eyes, where one stray
// ray of many may cross a surface's noise).
constexpr int kRaysAboveTheEyes = 4;

constexpr std::size_t index_of(SemanticClass c) {
  return static_cast<std::size_t>(c);
}

// What the points say about one cell.
struct CellEvidence {
  int floor = 0;
  // Points further below the floor than floor_tolerance: the views saw down past the floor there
  // (stairs down, a drop), which is then no floor, whatever passes over it.
  int below_floor = 0;
  std::array<int, kSemanticClassCount> band{};  // points in the robot's height band, per class
  // Band points within the spill margin of each side: -x, +x, -y, +y.
  std::array<int, 4> near_side{};
  float z_min = std::numeric_limits<float>::infinity();
  float z_max = -std::numeric_limits<float>::infinity();
  int band_views = 0;           // views with band points here (when views are known)
  std::int64_t last_view = -1;  // the view that added the last band point
  int band_total() const {
    int total = 0;
    for (std::size_t c = 0; c < band.size(); ++c) {
      if (c != index_of(SemanticClass::floor) && c != index_of(SemanticClass::ceiling))
        total += band[c];
    }
    return total;
  }
};

std::vector<double> heights_of(std::span<const Eigen::Vector3d> points,
                               std::span<const SemanticClass> labels, SemanticClass wanted) {
  std::vector<double> z;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (labels[i] == wanted && points[i].allFinite()) z.push_back(points[i].z());
  }
  return z;
}

std::optional<double> median_z(std::span<const Eigen::Vector3d> points,
                               std::span<const SemanticClass> labels, SemanticClass wanted) {
  std::vector<double> z = heights_of(points, labels, wanted);
  if (z.empty()) return std::nullopt;
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  return z[z.size() / 2];
}

// Fills an object's metric description from its cells: centre, main axis and extent along it,
// area, outline, height range.
// A preferred axis (a wall's run direction) replaces the principal one when they differ by more
// than 11.25 degrees: short thick blobs have no reliable principal axis.
void describe_cells(const SemanticGrid& grid, const Image<CellEvidence>& evidence,
                    SemanticObject& object, bool keep_axis = false,
                    const std::optional<Eigen::Vector2d>& preferred_axis = std::nullopt) {
  const double res = grid.resolution;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& c : object.cells) mean += grid.cell_center(c);
  mean /= static_cast<double>(object.cells.size());
  object.centre = mean;
  object.area = static_cast<double>(object.cells.size()) * res * res;

  if (!keep_axis) {
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& c : object.cells) {
      const Eigen::Vector2d d = grid.cell_center(c) - mean;
      cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    Eigen::Vector2d axis = eig.eigenvectors().col(1);
    if (preferred_axis && std::fabs(axis.dot(*preferred_axis)) < std::cos(std::numbers::pi / 16))
      axis = *preferred_axis;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& c : object.cells) {
      const double t = axis.dot(grid.cell_center(c) - mean);
      lo = std::min(lo, t), hi = std::max(hi, t);
    }
    object.axis_start = mean + (lo - 0.5 * res) * axis;
    object.axis_end = mean + (hi + 0.5 * res) * axis;
    object.width = (object.axis_end - object.axis_start).norm();
  }

  float z_min = std::numeric_limits<float>::infinity(), z_max = -z_min;
  int col0 = grid.width(), row0 = grid.height(), col1 = -1, row1 = -1;
  for (const auto& c : object.cells) {
    z_min = std::min(z_min, evidence(c.x(), c.y()).z_min);
    z_max = std::max(z_max, evidence(c.x(), c.y()).z_max);
    col0 = std::min(col0, c.x()), col1 = std::max(col1, c.x());
    row0 = std::min(row0, c.y()), row1 = std::max(row1, c.y());
  }
  if (std::isfinite(z_min)) object.z_min = z_min, object.z_max = z_max;

  // Outline: the largest external contour of the cell mask (1-cell frame so it closes).
  cv::Mat mask = cv::Mat::zeros(row1 - row0 + 3, col1 - col0 + 3, CV_8U);
  for (const auto& c : object.cells)
    mask.at<std::uint8_t>(c.y() - row0 + 1, c.x() - col0 + 1) = 255;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  const auto largest = std::max_element(contours.begin(), contours.end(),
                                        [](auto& a, auto& b) { return a.size() < b.size(); });
  object.contour.clear();
  if (largest != contours.end()) {
    for (const cv::Point& p : *largest)
      object.contour.push_back(grid.cell_center({p.x + col0 - 1, p.y + row0 - 1}));
  }
}

// The cells of each connected component of `mask` (8-connected unless told), in raster order.
std::vector<std::vector<Eigen::Vector2i>> components(
    const Image<std::uint8_t>& mask, Connectivity connectivity = Connectivity::eight) {
  const LabelImage labels = label_connected_components(mask, {connectivity, 1});
  std::vector<std::vector<Eigen::Vector2i>> out;
  for (int row = 0; row < mask.height(); ++row) {
    for (int col = 0; col < mask.width(); ++col) {
      const Label l = labels(col, row);
      if (!l) continue;
      if (out.size() < l) out.resize(l);
      out[l - 1].push_back({col, row});
    }
  }
  return out;
}

bool point_in_polygon(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& polygon) {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

// The cells where selected(col, row) holds as an 8-bit mask (255), and that mask closed with a
// size x size square (gaps of a few cells bridged).
struct CellMask {
  cv::Mat mask, closed;
};

template <typename Selected>
CellMask closed_cell_mask(const SemanticGrid& grid, const Selected& selected, int size) {
  CellMask m{cv::Mat(grid.height(), grid.width(), CV_8U), cv::Mat()};
  for (int row = 0; row < grid.height(); ++row)
    for (int col = 0; col < grid.width(); ++col)
      m.mask.at<std::uint8_t>(row, col) = selected(col, row) ? 255 : 0;
  cv::morphologyEx(m.mask, m.closed, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
  return m;
}

// The height above the floor at which a cell of furniture is judged seen through: its highest
// point, less a little so that the slab judged lies inside a 2-5 cm table top.
double judged_top(const SemanticGrid& grid, const Image<CellEvidence>& evidence, cv::Point cell) {
  return evidence(cell.x, cell.y).z_max - grid.floor_z - kBelowTop;
}

// A piece's cells' tops in levels (sorted, split where they step by more than kLevelStep): a
// level holding at least kLevelShare of them is a piece of furniture's own top (a table joined
// to a taller cabinet in one piece, a third of its cells).
constexpr double kLevelStep = 0.05, kLevelShare = 0.2;

// The median of each such level of the `sorted` tops but the one holding their median.
void add_levels(const std::vector<double>& sorted, std::vector<double>& tops) {
  const std::size_t median = sorted.size() / 2;
  std::size_t begin = 0;
  for (std::size_t end = 1; end <= sorted.size(); ++end) {
    if (end < sorted.size() && sorted[end] - sorted[end - 1] <= kLevelStep) continue;
    const bool own = begin <= median && median < end;
    if (!own &&
        static_cast<double>(end - begin) >= kLevelShare * static_cast<double>(sorted.size()))
      tops.push_back(sorted[(begin + end) / 2]);
    begin = end;
  }
}

// The tops of a piece of furniture (its cells' judged tops): the median and the 90th percentile,
// which differ where a table joins a taller cabinet; where the median is above what the views
// observe, the median of the tops they observe (a table joined to a larger shelf), if any; and
// the median of each other level that holds a large share of its cells (add_levels).
std::vector<double> piece_tops(const SemanticGrid& grid, const Image<CellEvidence>& evidence,
                               const detail::BandFreeSpace* free_space,
                               const std::vector<cv::Point>& cells) {
  std::vector<double> tops, observed;
  for (const cv::Point& c : cells) {
    const double top = judged_top(grid, evidence, c);
    if (!std::isfinite(top)) continue;
    tops.push_back(top);
    if (free_space && free_space->observable(top)) observed.push_back(top);
  }
  if (tops.empty()) return {std::numeric_limits<double>::quiet_NaN()};
  std::sort(tops.begin(), tops.end());
  std::sort(observed.begin(), observed.end());
  const double median = tops[tops.size() / 2];
  std::vector<double> judged{median, tops[tops.size() * 9 / 10]};
  if (free_space && !free_space->observable(median) && !observed.empty())
    judged.push_back(observed[observed.size() / 2]);
  add_levels(tops, judged);
  // A level's median may be one of the tops above: each is judged once.
  std::sort(judged.begin(), judged.end());
  judged.erase(std::unique(judged.begin(), judged.end()), judged.end());
  return judged;
}

// Whether a piece of furniture with these tops leaves `cell` open floor: the views saw through it
// in the few centimetres under each top (where a table's top stands), and, for a top above what
// they observe (a tall shelf), at every height they observe below it. Every height in the
// footprint of the piece's tall parts (`under_tall`): a shelf's boards stop the rays at heights
// of their own. Outside it, down to the highest top they observe: a table joined to a taller
// cabinet shadows the floor between them below its top, where rays to that floor pass through it.
bool open_beside(const detail::BandFreeSpace& free_space, const std::vector<double>& tops,
                 const cv::Point& cell, bool under_tall) {
  double highest_observed = 0;  // clear_between clamps it to the band's bottom
  for (const double top : tops)
    if (!under_tall && std::isfinite(top) && free_space.observable(top))
      highest_observed = std::max(highest_observed, top);
  return std::all_of(tops.begin(), tops.end(), [&](double top) {
    if (!std::isfinite(top)) return false;
    return free_space.observable(top)
               ? free_space.clear_between({cell.x, cell.y}, top - kTopDepth, top)
               : free_space.clear_between({cell.x, cell.y}, highest_observed, top);
  });
}

// The cells of `box` (a mask of its size) in the convex hull of the `marked` cells whose tops
// stand above the heights the views observe.
cv::Mat tall_footprint(const SemanticGrid& grid, const Image<CellEvidence>& evidence,
                       const detail::BandFreeSpace& free_space,
                       const std::vector<cv::Point>& marked, const cv::Rect& box) {
  std::vector<cv::Point> tall, hull;
  for (const cv::Point& c : marked) {
    const double top = judged_top(grid, evidence, c);
    if (std::isfinite(top) && !free_space.observable(top)) tall.push_back(c - box.tl());
  }
  cv::Mat footprint = cv::Mat::zeros(box.size(), CV_8U);
  if (tall.empty()) return footprint;
  cv::convexHull(tall, hull);
  cv::fillConvexPoly(footprint, hull, 255);
  return footprint;
}

// Wall cells that stand on nothing or reach no higher than a cabinet: the views saw under them
// (a table's edge or a shelf board the views took for a wall: walls stand on the floor), or saw
// through them just above their highest point (a low cabinet's front or side, which the views
// label as they label a wall: walls reach the ceiling, and no ray crosses a wall above its top).
// A cabinet's top is often above the views' eyes (a camera 1 m up, a cabinet 0.9-1.3 m tall):
// the rays that cross just above it then rise from the far side of the room to the wall behind it,
// few but enough to judge it by (kRaysAboveTheEyes).
bool wall_stands_apart(const CellEvidence& e, double floor_z,
                       const detail::BandFreeSpace& free_space, const Eigen::Vector2i& cell) {
  const double lowest = e.z_min - floor_z, highest = e.z_max - floor_z;
  if (lowest >= kRaisedWall && free_space.clear_below(cell, lowest - kBelowWall)) return true;
  if (!std::isfinite(highest)) return false;
  const double above = highest + kAboveWall;
  if (free_space.observable(above + kTopDepth))
    return free_space.clear_between(cell, above, above + kTopDepth);
  return free_space.fewest_passes(cell, above, above + kTopDepth) >= kRaysAboveTheEyes;
}

// A wall's face puts its depth noise into the room cell in front of it: a few of the face's
// points among the floor the views saw there, and rays crossing it at every height they observe.
// Such a cell beside a wall cell with `ratio` times its band points is the face's spill, and floor
// (a cell that stands on its own, a table's edge, has no such neighbour). The faces' placement
// frees such cells when they are wall and the face's points lie on a cell boundary; this takes
// those the views labelled otherwise (unclassified obstacles), and faces off the boundary.
int free_face_spill(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                    const detail::BandFreeSpace& free_space, const Image<std::uint8_t>& floor_seen,
                    double ratio, float floor_weight) {
  const auto spill_of_a_face = [&](const Eigen::Vector2i& c) {
    const int band = evidence(c.x(), c.y()).band_total();
    for (const Eigen::Vector2i& step : detail::kFourNeighbours) {
      const Eigen::Vector2i n = c + step;
      if (grid.contains(n) && grid.classes(n.x(), n.y()) == SemanticClass::wall &&
          evidence(n.x(), n.y()).band_total() >= ratio * band)
        return true;
    }
    return false;
  };
  std::vector<Eigen::Vector2i> freed;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i c(col, row);
      const bool obstacle =
          grid.classes(col, row) == SemanticClass::wall || detail::unclassified_obstacle(grid, c);
      if (obstacle && floor_seen(col, row) && free_space.clear_throughout(c) && spill_of_a_face(c))
        freed.push_back(c);
    }
  }
  detail::set_class(grid, freed, SemanticClass::floor, floor_weight);
  return static_cast<int>(freed.size());
}

// Such wall cells become unclassified obstacles, for the furniture passes to judge.
void raised_walls_to_unclassified(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                                  const detail::BandFreeSpace& free_space, float weight) {
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      if (grid.classes(col, row) != SemanticClass::wall ||
          !wall_stands_apart(evidence(col, row), grid.floor_z, free_space, {col, row}))
        continue;
      grid.classes(col, row) = SemanticClass::unknown;
      grid.weight(col, row) = weight;
    }
  }
}

// The rectangle around a piece's outline, turned to the outline's own directions (the length-
// weighted mean of its edges' angles modulo 90 degrees): an L of a table's two edges gives the
// table, where the smallest rectangle around an L may lie along its diagonal.
std::vector<cv::Point> rectangle_around(const std::vector<cv::Point>& outline) {
  double s = 0, c = 0;
  for (std::size_t i = 0; i < outline.size(); ++i) {
    const cv::Point d = outline[(i + 1) % outline.size()] - outline[i];
    const double length = std::hypot(d.x, d.y), angle = std::atan2(d.y, d.x);
    s += length * std::sin(4 * angle), c += length * std::cos(4 * angle);
  }
  const double angle = std::atan2(s, c) / 4;
  const Eigen::Vector2d u(std::cos(angle), std::sin(angle)), v(-u.y(), u.x());
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const cv::Point& p : outline) {
    const Eigen::Vector2d q(u.dot(Eigen::Vector2d(p.x, p.y)), v.dot(Eigen::Vector2d(p.x, p.y)));
    lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  }
  std::vector<cv::Point> corners;
  for (const Eigen::Vector2d& q :
       {lo, Eigen::Vector2d(hi.x(), lo.y()), hi, Eigen::Vector2d(lo.x(), hi.y())}) {
    const Eigen::Vector2d p = q.x() * u + q.y() * v;
    corners.push_back({static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y()))});
  }
  return corners;
}

// Fills one piece of furniture within `hull` (fill_furniture's shape of it), but for the cells
// that the views saw through just under the piece's tops when the free space is known (open floor
// in the hull of an L or of two pieces, the shadow behind a table).
void fill_piece(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                const detail::BandFreeSpace* free_space, Image<std::uint8_t>& furniture,
                std::vector<cv::Point> hull, float furniture_weight) {
  const cv::Rect box = cv::boundingRect(hull) & cv::Rect(0, 0, grid.width(), grid.height());
  cv::Mat fill = cv::Mat::zeros(box.height, box.width, CV_8U);
  for (cv::Point& p : hull) p -= box.tl();
  cv::fillConvexPoly(fill, hull, 255);
  std::vector<cv::Point> cells, marked;
  for (int y = 0; y < box.height; ++y) {
    for (int x = 0; x < box.width; ++x) {
      if (!fill.at<std::uint8_t>(y, x)) continue;
      cells.push_back(box.tl() + cv::Point(x, y));
      if (furniture(cells.back().x, cells.back().y)) marked.push_back(cells.back());
    }
  }
  const std::vector<double> tops = piece_tops(grid, evidence, free_space, marked);
  const cv::Mat tall =
      free_space ? tall_footprint(grid, evidence, *free_space, marked, box) : cv::Mat();
  for (const cv::Point& c : cells) {
    // Only floor changes: walls and doors keep their class, and what no view saw stays
    // unknown (filling it made rooms leak where the views were few).
    if (furniture(c.x, c.y) || grid.classes(c.x, c.y) != SemanticClass::floor ||
        (free_space && open_beside(*free_space, tops, c, tall.at<std::uint8_t>(c - box.tl()) != 0)))
      continue;
    furniture(c.x, c.y) = 1;
    grid.classes(c.x, c.y) = SemanticClass::furniture;
    grid.weight(c.x, c.y) = furniture_weight;
  }
}

// The pieces of the furniture cells `marked` (a mask) inside a closed piece (its outline), taken
// apart where walls cross the piece and each side closed again over `size` cells: no furniture
// stands across a wall, and a piece joined over one (a layer on one face, specks in the room
// beyond) has a hull over the room's floor between them. A piece no wall crosses is itself.
std::vector<std::vector<cv::Point>> pieces_between_walls(const std::vector<cv::Point>& outline,
                                                         const cv::Mat& marked,
                                                         const cv::Mat& walls, int size) {
  const cv::Rect box = cv::boundingRect(outline);
  cv::Mat inside = cv::Mat::zeros(box.size(), CV_8U);
  cv::drawContours(inside, std::vector<std::vector<cv::Point>>{outline}, 0, 255, cv::FILLED,
                   cv::LINE_8, cv::noArray(), 0, -box.tl());
  if (cv::countNonZero(inside & walls(box)) == 0) return {outline};
  inside.setTo(0, walls(box));
  std::vector<std::vector<cv::Point>> sides, pieces;
  cv::findContours(inside.clone(), sides, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  if (sides.size() <= 1) return {outline};
  for (std::size_t k = 0; k < sides.size(); ++k) {
    cv::Mat side = cv::Mat::zeros(box.size(), CV_8U), closed;
    cv::drawContours(side, sides, static_cast<int>(k), 255, cv::FILLED);
    cv::morphologyEx(side & marked(box), closed, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
    std::vector<std::vector<cv::Point>> found;
    cv::findContours(closed, found, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE, box.tl());
    pieces.insert(pieces.end(), found.begin(), found.end());
  }
  return pieces;
}

// A depth edge's mixed pixels pile up in a cell one or two a view (a line of them along a view's
// ray behind a table's or a cabinet's outline); a surface puts tens of points a view in a cell.
constexpr double kMixedPixelsPerView = 5;

// Whether a cell's band points are that sparse: fewer than kMixedPixelsPerView for each view that
// put points in it.
bool mixed_pixels_only(const CellEvidence& e) {
  return e.band_views > 0 && e.band_total() < kMixedPixelsPerView * e.band_views;
}

// One closing of fill_furniture's: its size in cells, and whether the mixed pixels take part.
struct JoinPass {
  int size;
  bool solid_only;
};

// Furniture seen as outlines (a table's legs and edges; its top drops out at grazing views): each
// piece, closed over gaps of join_gap, whose convex hull is at most max_area is filled
// (fill_piece): the robot cannot drive under it within its height band. The marked cells of a
// piece too large (the tables and cabinets of a room joined into one) are judged again without
// the cells of mixed pixels only, then closed over kJoinAgainGap.
void fill_furniture(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                    const detail::BandFreeSpace* free_space, Image<std::uint8_t>& furniture,
                    double join_gap, double max_area, float furniture_weight) {
  constexpr double kJoinAgainGap = 0.35;  // m: the join gap before phantom points were dropped
  const auto cells_of = [&](double gap) {
    return std::max(1, static_cast<int>(std::lround(gap / grid.resolution)));
  };
  cv::Mat left = closed_cell_mask(
                     grid, [&](int col, int row) { return furniture(col, row) != 0; }, 1)
                     .mask;
  const cv::Mat solid = closed_cell_mask(
                            grid,
                            [&](int col, int row) {
                              return furniture(col, row) && !mixed_pixels_only(evidence(col, row));
                            },
                            1)
                            .mask;
  const double cell_area = grid.resolution * grid.resolution;
  // A piece too large over all its cells is judged again without its mixed pixels (a line of
  // them joins a table to its neighbours), then over the smaller gap.
  std::vector<JoinPass> passes{{cells_of(join_gap), false}, {cells_of(join_gap), true}};
  if (cells_of(kJoinAgainGap) < passes.front().size)
    passes.push_back({cells_of(kJoinAgainGap), false});
  const cv::Mat walls =
      closed_cell_mask(
          grid, [&](int col, int row) { return grid.classes(col, row) == SemanticClass::wall; }, 1)
          .mask;
  for (const JoinPass& pass : passes) {
    const int size = pass.size;
    const cv::Mat input = pass.solid_only ? cv::Mat(left & solid) : left;
    // Without mixed pixels among what is left, the pass would judge the same pieces again.
    if (pass.solid_only && cv::countNonZero(left) == cv::countNonZero(input)) continue;
    cv::Mat closed;
    cv::morphologyEx(input, closed, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
    std::vector<std::vector<cv::Point>> pieces;
    cv::findContours(closed, pieces, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    cv::Mat too_large = cv::Mat::zeros(left.size(), CV_8U);
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      std::vector<cv::Point> hull;
      cv::convexHull(pieces[k], hull);
      if (cv::contourArea(hull) * cell_area > max_area) {
        cv::drawContours(too_large, pieces, static_cast<int>(k), 255, cv::FILLED);
        continue;
      }
      for (const std::vector<cv::Point>& part :
           pieces_between_walls(pieces[k], input, walls, size)) {
        cv::convexHull(part, hull);
        // What the piece fills: with the free space, the rectangle around it, where that is
        // furniture sized too; pieces joined in an L (a table and a cabinet beside it) have a
        // hull of furniture size and a rectangle over the open floor between them.
        if (free_space) {
          std::vector<cv::Point> rectangle = rectangle_around(part);
          if (cv::contourArea(rectangle) * cell_area <= max_area) hull = std::move(rectangle);
        }
        fill_piece(grid, evidence, free_space, furniture, hull, furniture_weight);
      }
    }
    // What is left for the next pass: the pieces too large, and after the pass without the
    // mixed pixels, those no piece took.
    cv::bitwise_and(left, pass.solid_only ? cv::Mat(~closed | too_large) : too_large, left);
  }
}

// A table's leg: a post of furniture or unnamed obstacle cells whose points are solid (not a depth
// edge's mixed pixels), start within kLegFoot of the band's bottom and reach kMinLegHeight or
// higher, but no higher than furniture; at most kMaxLegCells across, with no wall beside it.
constexpr double kLegFoot = 0.1, kMinLegHeight = 0.3;
constexpr int kMaxLegCells = 3;

bool leg_cell(const SemanticGrid& grid, const CellEvidence& e, const Eigen::Vector2i& c,
              const SemanticGridParams& options) {
  const bool obstacle = grid.classes(c.x(), c.y()) == SemanticClass::furniture ||
                        detail::unclassified_obstacle(grid, c);
  const double bottom = e.z_min - grid.floor_z, top = e.z_max - grid.floor_z;
  return obstacle && e.band_views > 0 && !mixed_pixels_only(e) &&
         bottom <= options.band_min + kLegFoot && top >= kMinLegHeight &&
         top <= options.furniture_max_height;
}

std::vector<detail::TableLeg> table_legs(const SemanticGrid& grid,
                                         const Image<CellEvidence>& evidence,
                                         const SemanticGridParams& options) {
  Image<std::uint8_t> mask(grid.width(), grid.height(), 0);
  for (int row = 0; row < grid.height(); ++row)
    for (int col = 0; col < grid.width(); ++col)
      mask(col, row) = leg_cell(grid, evidence(col, row), {col, row}, options);
  std::vector<detail::TableLeg> legs;
  for (std::vector<Eigen::Vector2i>& cells : components(mask)) {
    Eigen::Vector2i lo = cells.front(), hi = cells.front();
    bool beside_wall = false;
    detail::TableLeg leg;
    for (const Eigen::Vector2i& c : cells) {
      lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
      leg.top = std::max(leg.top, double{evidence(c.x(), c.y()).z_max} - grid.floor_z);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          beside_wall |= detail::seen_as(grid, c + Eigen::Vector2i(dx, dy), SemanticClass::wall);
    }
    if (beside_wall || (hi - lo).maxCoeff() >= kMaxLegCells) continue;
    leg.cells = std::move(cells);
    legs.push_back(std::move(leg));
  }
  return legs;
}

// Tables seen by their legs (grid_tables.hpp), after the fill: the legs of a table longer than
// the join gap stand apart, and its edges join only where the views saw them. The fill's cells
// joined to such a table beyond its top are floor again; `marked` holds the furniture cells the
// views saw, before the fill. Both are counted in the grid.
void tables_on_legs(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                    const detail::BandFreeSpace& free_space, const SemanticGridParams& options,
                    const Image<std::uint8_t>& marked, Image<std::uint8_t>& furniture) {
  constexpr double kMinLegSpacing = 0.3;  // m: a table's legs stand farther apart
  const double res = grid.resolution;
  const detail::LegLimits limits{kMinLegSpacing / res, options.furniture_max_extent / res,
                                 options.max_furniture_fill_area / (res * res)};
  const std::vector<detail::LegTable> tables =
      detail::fill_tables_on_legs(grid, table_legs(grid, evidence, options), limits, free_space,
                                  options.weights.of(SemanticClass::furniture), furniture);
  grid.inferred.tables_on_legs = static_cast<int>(tables.size());
  grid.inferred.fill_cells_trimmed_at_tables = detail::trim_fills_around_tables(
      grid, tables, marked, options.weights.of(SemanticClass::floor), furniture);
}

// The pieces of `mask` closed with a size x size square (8-connected): each piece's cells of the
// mask, and the highest point over them.
struct MaskPieces {
  std::vector<std::vector<cv::Point>> cells;
  std::vector<float> top;
};

MaskPieces mask_pieces(const cv::Mat& mask, int size, const Image<CellEvidence>& evidence) {
  cv::Mat closed, labels;
  cv::morphologyEx(mask, closed, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
  const int count = cv::connectedComponents(closed, labels, 8, CV_32S);
  MaskPieces pieces{
      std::vector<std::vector<cv::Point>>(static_cast<std::size_t>(count)),
      std::vector<float>(static_cast<std::size_t>(count), -std::numeric_limits<float>::infinity())};
  for (int row = 0; row < mask.rows; ++row) {
    for (int col = 0; col < mask.cols; ++col) {
      const auto piece = static_cast<std::size_t>(labels.at<int>(row, col));
      if (piece == 0 || !mask.at<std::uint8_t>(row, col)) continue;
      pieces.cells[piece].push_back({col, row});
      pieces.top[piece] = std::max(pieces.top[piece], evidence(col, row).z_max);
    }
  }
  return pieces;
}

// Pieces of unclassified obstacle or furniture cells, closed over gaps of a few cells like
// fill_furniture's, that are furniture sized and low: their unclassified cells become furniture.
// A piece too large for furniture is looked at again closed over smaller gaps (pieces of furniture
// along one wall join over the gaps between them), down to its cells as they are.
void unclassified_to_furniture(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                               const SemanticGridParams& options, Image<std::uint8_t>& furniture) {
  auto unclassified = [&](int col, int row) {
    return detail::unclassified_obstacle(grid, {col, row});
  };
  cv::Mat mask =
      closed_cell_mask(
          grid, [&](int col, int row) { return unclassified(col, row) || furniture(col, row); }, 1)
          .mask;
  const double cell_area = grid.resolution * grid.resolution;
  for (const int size : {7, 3, 1}) {
    const MaskPieces pieces = mask_pieces(mask, size, evidence);
    mask.setTo(0);  // what is left for the next, smaller closing: the pieces too large
    for (std::size_t k = 1; k < pieces.cells.size(); ++k) {
      const std::vector<cv::Point>& cells = pieces.cells[k];
      if (cells.empty() || pieces.top[k] - grid.floor_z > options.furniture_max_height) continue;
      std::vector<cv::Point> hull;
      cv::convexHull(cells, hull);
      const cv::RotatedRect box = cv::minAreaRect(cells);
      const double extent = (std::max(box.size.width, box.size.height) + 1) * grid.resolution;
      if (cv::contourArea(hull) * cell_area > options.max_furniture_fill_area ||
          extent > options.furniture_max_extent) {
        for (const cv::Point& c : cells) mask.at<std::uint8_t>(c.y, c.x) = 255;
        continue;
      }
      for (const cv::Point& c : cells) {
        if (!unclassified(c.x, c.y)) continue;
        furniture(c.x, c.y) = 1;
        grid.classes(c.x, c.y) = SemanticClass::furniture;
        grid.weight(c.x, c.y) = options.weights.of(SemanticClass::furniture);
      }
    }
  }
}

// Unobserved runs along rows and columns with cells of class `ends` at both ends, at most
// max_cells long, become `ends`: the inside of a wall seen from both sides; floor that the views
// missed in a thin shadow behind a corner (a fan of them where the robot turns in place).
void fill_unobserved_runs(SemanticGrid& grid, SemanticClass ends, int max_cells, float weight,
                          const Image<std::uint8_t>* keep = nullptr) {
  const auto is_end = [&](const Eigen::Vector2i& c) { return grid.classes(c.x(), c.y()) == ends; };
  for (const Eigen::Vector2i& c : detail::unobserved_runs_between(grid, is_end, 0, max_cells)) {
    if (keep && (*keep)(c.x(), c.y())) continue;
    grid.classes(c.x(), c.y()) = ends;
    grid.weight(c.x(), c.y()) = weight;
  }
}

// The cells no view saw (a mask).
Image<std::uint8_t> unobserved_cells(const SemanticGrid& grid) {
  Image<std::uint8_t> unseen(grid.width(), grid.height(), 0);
  for (int row = 0; row < grid.height(); ++row)
    for (int col = 0; col < grid.width(); ++col)
      unseen(col, row) = detail::unobserved(grid, {col, row});
  return unseen;
}

// The drops: each piece of unseen cells (4-neighbours) where the views saw below the floor in a
// cell, whole. A stairwell's far part returns its steps; its near part, hidden under the edge,
// returns nothing, and rays pass over both as over floor the camera lost at grazing angles.
Image<std::uint8_t> drop_regions(const SemanticGrid& grid, const Image<std::uint8_t>& below) {
  const Image<std::uint8_t> unseen = unobserved_cells(grid);
  Image<std::uint8_t> drops(grid.width(), grid.height(), 0);
  for (const std::vector<Eigen::Vector2i>& piece : components(unseen, Connectivity::four)) {
    const bool drop = std::any_of(piece.begin(), piece.end(),
                                  [&](const Eigen::Vector2i& c) { return below(c.x(), c.y()); });
    if (drop)
      for (const Eigen::Vector2i& c : piece) drops(c.x(), c.y()) = 1;
  }
  return drops;
}

// The share of a hole's cells that must lie on runs with seen floor at both ends: all but the few
// rows that poke into the noise of the walls' faces along a corridor.
constexpr double kHoleOnFloorRuns = 0.9;

// Whether kHoleOnFloorRuns of the hole's cells lie on runs along `along` (its rows or columns)
// with seen floor at both ends.
bool floor_at_run_ends(const SemanticGrid& grid, std::span<const Eigen::Vector2i> hole,
                       const Eigen::Vector2i& along) {
  std::size_t on_floor_runs = 0;
  for (const Eigen::Vector2i& start : hole) {
    if (detail::unobserved(grid, start - along)) continue;  // not a run's first cell
    Eigen::Vector2i end = start;
    while (detail::unobserved(grid, end)) end += along;
    if (detail::seen_as(grid, start - along, SemanticClass::floor) &&
        detail::seen_as(grid, end, SemanticClass::floor))
      on_floor_runs += static_cast<std::size_t>((end - start).cwiseAbs().sum());
  }
  return static_cast<double>(on_floor_runs) >= kHoleOnFloorRuns * static_cast<double>(hole.size());
}

// How far beyond a hole's side a wall may stand behind the noise of its face (furniture or
// unnamed obstacles the views made of it) [m].
constexpr double kWallBehindSide = 0.4;

// Whether every seen neighbour of the hole along `across` (either way) is floor, or has a wall or
// an unseen cell (the wall's inside, the hole again around a speck) behind it within
// kWallBehindSide, with no floor before it: the hole's sides are floor or walls, not an object
// with floor behind it, which may stand in the hole.
bool walled_across(const SemanticGrid& grid, std::span<const Eigen::Vector2i> hole,
                   const Eigen::Vector2i& across) {
  const int reach = static_cast<int>(std::ceil(kWallBehindSide / grid.resolution));
  const auto floor_or_wall_behind = [&](Eigen::Vector2i n, const Eigen::Vector2i& out) {
    if (detail::seen_as(grid, n, SemanticClass::floor)) return true;
    for (int k = 0; k < reach && grid.contains(n); ++k, n += out) {
      if (detail::unobserved(grid, n) || detail::seen_as(grid, n, SemanticClass::wall)) return true;
      if (detail::seen_as(grid, n, SemanticClass::floor)) return false;
    }
    return false;
  };
  for (const Eigen::Vector2i& c : hole) {
    for (const Eigen::Vector2i& out : {across, Eigen::Vector2i(-across)}) {
      const Eigen::Vector2i n = c + out;
      if (!grid.contains(n)) return false;
      if (!detail::unobserved(grid, n) && !floor_or_wall_behind(n, out)) return false;
    }
  }
  return true;
}

// Whether every 4-neighbour of the hole's cells is unseen or seen floor.
bool enclosed_by_floor(const SemanticGrid& grid, std::span<const Eigen::Vector2i> hole) {
  return std::all_of(hole.begin(), hole.end(), [&](const Eigen::Vector2i& c) {
    return std::all_of(
        detail::kFourNeighbours.begin(), detail::kFourNeighbours.end(),
        [&](const Eigen::Vector2i& d) {
          const Eigen::Vector2i n = c + d;
          return grid.contains(n) &&
                 (detail::unobserved(grid, n) || detail::seen_as(grid, n, SemanticClass::floor));
        });
  });
}

// Whether the hole lies between seen floor along its rows or along its columns (kHoleOnFloorRuns of
// its cells on runs with seen floor at both ends), with floor or walls at its sides across them.
// Nothing stands in such a hole, or the views of the floor on its two sides would have seen it: a
// stretch of corridor between its walls that the views from its two ends lost at grazing angles
// (held-out survey seed 23's corridor had been cut in two by one). Beside an object's face with
// floor behind it, the object may stand in the hole.
bool between_floor_and_walls(const SemanticGrid& grid, std::span<const Eigen::Vector2i> hole) {
  for (const Eigen::Vector2i& along : {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1)}) {
    if (floor_at_run_ends(grid, hole, along) &&
        walled_across(grid, hole, Eigen::Vector2i(along.y(), along.x())))
      return true;
  }
  return false;
}

// Unseen holes (4-neighbours) up to max_area [m^2] where `fillable` holds are floor
// (SemanticGridParams::max_floor_hole), unless the views saw below the floor in them.
template <typename Fillable>
void fill_floor_holes(SemanticGrid& grid, double max_area, float weight,
                      const Image<std::uint8_t>& drops, const Fillable& fillable) {
  const Image<std::uint8_t> unseen = unobserved_cells(grid);
  const auto max_cells = static_cast<std::size_t>(max_area / (grid.resolution * grid.resolution));
  for (const std::vector<Eigen::Vector2i>& hole : components(unseen, Connectivity::four)) {
    if (hole.size() > max_cells) continue;
    const bool drop = std::any_of(hole.begin(), hole.end(), [&](const Eigen::Vector2i& c) {
      return drops(c.x(), c.y()) != 0;
    });
    if (!drop && fillable(std::span<const Eigen::Vector2i>(hole)))
      detail::set_class(grid, hole, SemanticClass::floor, weight);
  }
}

// Unclassified obstacles that enclose floor (the legs and edges of a table whose top dropped out of
// grazing views; M2 has no furniture rule): each enclosed hole of at most max_area is obstacle.
// Only closed loops count: an L of clutter along two walls encloses nothing.
void fill_enclosed_by_unclassified(SemanticGrid& grid, double max_area, float weight) {
  const int w = grid.width(), h = grid.height();
  const auto unclassified = [&](int col, int row) {
    return detail::unclassified_obstacle(grid, {col, row});
  };
  cv::Mat closed = closed_cell_mask(grid, unclassified, 5).closed;
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(closed, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_SIMPLE);
  cv::Mat fill = cv::Mat::zeros(h, w, CV_8U);
  const double cell_area = grid.resolution * grid.resolution;
  for (std::size_t k = 0; k < contours.size(); ++k) {
    const bool hole = hierarchy[k][3] >= 0;
    if (hole && cv::contourArea(contours[k]) * cell_area <= max_area)
      cv::drawContours(fill, contours, static_cast<int>(k), 255, cv::FILLED);
  }
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      if (!fill.at<std::uint8_t>(row, col) || grid.classes(col, row) != SemanticClass::floor)
        continue;
      grid.classes(col, row) = SemanticClass::unknown;
      grid.weight(col, row) = weight;
    }
  }
}

// A surface on the boundary between two cells (the synthetic world's walls lie on the 5 cm
// lattice) puts noisy points on both sides of it. The cell that sees floor and whose band points
// hug the side facing an obstacle cell with less floor is free: the surface belongs to the other.
void remove_spill(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                  const SemanticGridParams& options, Image<std::uint8_t>& leaf,
                  Image<std::uint8_t>& furniture) {
  const std::array<Eigen::Vector2i, 4> sides = {Eigen::Vector2i(-1, 0), Eigen::Vector2i(1, 0),
                                                Eigen::Vector2i(0, 1), Eigen::Vector2i(0, -1)};
  std::vector<Eigen::Vector2i> spilled;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const CellEvidence& e = evidence(col, row);
      if (!(grid.weight(col, row) == 0.0f || leaf(col, row)) || e.floor < options.min_floor_points)
        continue;
      const int band = e.band_total();
      for (int s = 0; s < 4; ++s) {
        const Eigen::Vector2i n = Eigen::Vector2i(col, row) + sides[s];
        if (!grid.contains(n) || evidence(n.x(), n.y()).floor >= e.floor) continue;
        if (!(grid.weight(n.x(), n.y()) == 0.0f || leaf(n.x(), n.y()))) continue;
        if (e.near_side[s] >= options.spill_fraction * band) {
          spilled.push_back({col, row});
          break;
        }
      }
    }
  }
  for (const auto& c : spilled) {
    grid.classes(c.x(), c.y()) = SemanticClass::floor;
    grid.weight(c.x(), c.y()) = options.weights.of(SemanticClass::floor);
    leaf(c.x(), c.y()) = 0, furniture(c.x(), c.y()) = 0;
  }
}

// The cells whose evidence meets `holds` (a mask).
template <typename Holds>
Image<std::uint8_t> cells_where(const Image<CellEvidence>& evidence, Holds holds) {
  Image<std::uint8_t> mask(evidence.width(), evidence.height(), 0);
  for (int row = 0; row < evidence.height(); ++row)
    for (int col = 0; col < evidence.width(); ++col) mask(col, row) = holds(evidence(col, row));
  return mask;
}

// The cells where the views saw below the floor.
Image<std::uint8_t> below_floor_seen(const Image<CellEvidence>& evidence) {
  return cells_where(evidence, [](const CellEvidence& e) { return e.below_floor > 0; });
}

// The cells where floor was seen.
Image<std::uint8_t> floor_seen(const Image<CellEvidence>& evidence,
                               const SemanticGridParams& options) {
  return cells_where(evidence,
                     [&](const CellEvidence& e) { return e.floor >= options.min_floor_points; });
}

bool is_obstacle(float weight_value) {
  return weight_value == 0.0f;
}

// Obstacle cells with no obstacle among their 8 neighbours become what their floor evidence says,
// but for posts (leg_cell: solid points from the floor up, furniture or unnamed): a table's or a
// chair's leg inside one cell, which the robot must not drive into and the tables seen by their
// legs need.
void remove_isolated_obstacles(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                               const SemanticGridParams& options, Image<std::uint8_t>& leaf,
                               Image<std::uint8_t>& furniture) {
  std::vector<Eigen::Vector2i> specks;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      if (!is_obstacle(grid.weight(col, row)) && !leaf(col, row)) continue;
      bool alone = true;
      for (int dy = -1; dy <= 1 && alone; ++dy) {
        for (int dx = -1; dx <= 1 && alone; ++dx) {
          const Eigen::Vector2i n(col + dx, row + dy);
          if ((dx || dy) && grid.contains(n) &&
              (is_obstacle(grid.weight(n.x(), n.y())) || leaf(n.x(), n.y())))
            alone = false;
        }
      }
      if (!alone) continue;
      if (leg_cell(grid, evidence(col, row), {col, row}, options))
        ++grid.inferred.lone_posts_kept;
      else
        specks.push_back({col, row});
    }
  }
  for (const auto& c : specks) {
    const bool floor = evidence(c.x(), c.y()).floor >= options.min_floor_points;
    grid.classes(c.x(), c.y()) = floor ? SemanticClass::floor : SemanticClass::unknown;
    grid.weight(c.x(), c.y()) = floor ? options.weights.of(SemanticClass::floor) : kUnobserved;
    leaf(c.x(), c.y()) = 0, furniture(c.x(), c.y()) = 0;
  }
}

void check_inputs(std::span<const Eigen::Vector3d> points, std::span<const SemanticClass> labels,
                  const SemanticGridParams& options) {
  options.validate();
  require(points.size() == labels.size(), "build_semantic_grid: " + std::to_string(points.size()) +
                                              " points but " + std::to_string(labels.size()) +
                                              " labels");
  for (const SemanticClass c : labels) {
    require(static_cast<int>(c) < kSemanticClassCount, "build_semantic_grid: label value " +
                                                           std::to_string(static_cast<int>(c)) +
                                                           " is no SemanticClass");
  }
}

// A grid over the points' extent (plus the margin), every cell unobserved, with its floor and
// ceiling heights (given or the median of their points).
SemanticGrid empty_grid(std::span<const Eigen::Vector3d> points,
                        std::span<const SemanticClass> labels, const SemanticGridParams& options) {
  SemanticGrid grid;
  grid.resolution = options.resolution;
  grid.weights = options.weights;
  grid.floor_z = options.floor_z.value_or(
      floor_level(heights_of(points, labels, SemanticClass::floor)).value_or(0.0));
  grid.ceiling_z =
      options.ceiling_z ? options.ceiling_z : median_z(points, labels, SemanticClass::ceiling);

  // Extent from the data, the origin on a multiple of the resolution (so grids of one world align).
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p.head<2>()), hi = hi.cwiseMax(p.head<2>());
  }
  require(std::isfinite(lo.x()),
          "build_semantic_grid: no finite point among " + std::to_string(points.size()));
  const double res = options.resolution;
  if (options.align_cells_to_walls) {
    const detail::FacePhase faces =
        detail::wall_face_phase(points, labels, grid.floor_z, options, kMinFaceCrispness);
    grid.inferred.lattice_offset = faces.offset;
    grid.inferred.wall_face_crispness = faces.crispness;
  }
  const Eigen::Vector2d& phase = grid.inferred.lattice_offset;
  grid.origin = (((lo - phase).array() - options.margin) / res).floor() * res + phase.array();
  const Eigen::Vector2i size =
      ((hi.array() + options.margin - grid.origin.array()) / res).ceil().cast<int>().max(1);
  require(static_cast<double>(size.x()) * size.y() < 1e8,
          "build_semantic_grid: the points span " + std::to_string(size.x()) + " x " +
              std::to_string(size.y()) + " cells: too many (outliers far away?)");
  // The grid's images and the per-cell evidence and masks below, twice for the working copies.
  const double cell_bytes =
      2.0 * (sizeof(SemanticClass) + sizeof(float) + sizeof(std::vector<int>) +
             sizeof(CellEvidence) + 2 * sizeof(std::uint8_t));
  require_fits_in_memory(cell_bytes * size.x() * size.y(),
                         "build_semantic_grid: a grid of " + std::to_string(size.x()) + " x " +
                             std::to_string(size.y()) + " cells at " + std::to_string(res) + " m");
  grid.classes = Image<SemanticClass>(size.x(), size.y(), SemanticClass::unknown);
  grid.weight = Image<float>(size.x(), size.y(), kUnobserved);
  grid.cell_objects = Image<std::vector<int>>(size.x(), size.y());
  return grid;
}

// What the points say about each cell of `grid`; phantom points (phantom[i] != 0; empty: none)
// say nothing.
Image<CellEvidence> gather_evidence(const SemanticGrid& grid,
                                    std::span<const Eigen::Vector3d> points,
                                    std::span<const SemanticClass> labels,
                                    std::span<const std::uint32_t> view_ids,
                                    std::span<const std::uint8_t> phantom,
                                    const SemanticGridParams& options) {
  const double res = options.resolution;
  Image<CellEvidence> evidence(grid.width(), grid.height());
  const double below_ceiling = grid.ceiling_z
                                   ? *grid.ceiling_z - grid.floor_z - options.ceiling_margin
                                   : std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if (!p.allFinite() || (!phantom.empty() && phantom[i])) continue;
    const Eigen::Vector2i cell = grid.cell_of(p.head<2>());
    CellEvidence& e = evidence(cell.x(), cell.y());
    const double h = p.z() - grid.floor_z;
    const SemanticClass c = labels[i];
    if (h < -options.floor_tolerance) {
      ++e.below_floor;
      continue;
    }
    if (c == SemanticClass::floor) {
      if (std::fabs(h) <= options.floor_tolerance) ++e.floor;
      continue;  // a floor label far from the floor is a bad label, not an obstacle
    }
    if (c == SemanticClass::ceiling) continue;
    if (h >= options.band_min && h <= options.band_max) {
      ++e.band[index_of(c)];
      const std::int64_t view = view_ids.empty() ? -1 : std::int64_t{view_ids[i]};
      if (view != e.last_view) ++e.band_views, e.last_view = view;
      const Eigen::Vector2d local =
          p.head<2>() - grid.cell_center(cell) + Eigen::Vector2d::Constant(0.5 * res);
      const double m = options.spill_margin;
      e.near_side[0] += local.x()<m, e.near_side[1] += local.x()> res - m;
      e.near_side[2] += local.y()<m, e.near_side[3] += local.y()> res - m;
    }
    if (h >= options.band_min && h < below_ceiling) {
      e.z_min = std::min(e.z_min, static_cast<float>(p.z()));
      e.z_max = std::max(e.z_max, static_cast<float>(p.z()));
    }
  }
  return evidence;
}

// Distinct views among ascending view ids (0 when none are given).
int count_views(std::span<const std::uint32_t> view_ids) {
  int views = 0;
  for (std::size_t i = 0; i < view_ids.size(); ++i)
    views += i == 0 || view_ids[i] != view_ids[i - 1];
  return views;
}

// The most frequent class of a cell's band points (floor and ceiling aside; the first on ties).
SemanticClass dominant_band_class(const CellEvidence& e) {
  std::size_t best = 0;
  for (std::size_t k = 0; k < e.band.size(); ++k) {
    if (k == index_of(SemanticClass::floor) || k == index_of(SemanticClass::ceiling)) continue;
    if (e.band[k] > e.band[best]) best = k;
  }
  return static_cast<SemanticClass>(best);
}

// The cells of door leaves and of furniture, which become objects of their own.
struct ObstacleMasks {
  Image<std::uint8_t> leaf, furniture;
};

// Each cell's class and weight from its evidence: obstacle evidence first, then floor.
ObstacleMasks classify_cells(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                             const SemanticGridParams& options) {
  const int w = grid.width(), h = grid.height();
  ObstacleMasks masks{Image<std::uint8_t>(w, h, 0), Image<std::uint8_t>(w, h, 0)};
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      const CellEvidence& e = evidence(col, row);
      SemanticClass c = SemanticClass::unknown;
      float weight = kUnobserved;
      const int band = e.band_total();
      const bool views_agree = e.last_view < 0 || e.band_views >= options.min_obstacle_views;
      if (band >= options.min_obstacle_points && views_agree &&
          band >= options.min_obstacle_floor_ratio * e.floor) {
        c = dominant_band_class(e);
        weight = c == SemanticClass::unknown ? options.weights.unclassified_obstacle
                                             : options.weights.of(c);
        masks.leaf(col, row) = c == SemanticClass::door;
        masks.furniture(col, row) = c == SemanticClass::furniture;
      } else if (e.floor >= options.min_floor_points) {
        c = SemanticClass::floor;
        weight = options.weights.of(c);
      }
      grid.classes(col, row) = c;
      grid.weight(col, row) = weight;
    }
  }
  return masks;
}

// Appends an object of `cells` to the grid, described from its cells, and returns it.
SemanticObject& append_object(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                              ObjectKind kind, SemanticClass label, const std::string& name,
                              std::vector<Eigen::Vector2i> cells) {
  SemanticObject object;
  object.id = static_cast<int>(grid.objects.size()) + 1;
  object.kind = kind;
  object.label = label;
  object.name = name;
  object.cells = std::move(cells);
  describe_cells(grid, evidence, object);
  grid.objects.push_back(std::move(object));
  return grid.objects.back();
}

// Door leaves, then furniture: one object per connected piece of their masks.
void add_obstacle_objects(ObstacleMasks& masks, const detail::AddObject& add_object) {
  int leaf_count = 0;
  for (auto& cells : components(masks.leaf))
    add_object(ObjectKind::door_leaf, SemanticClass::door, "door " + std::to_string(++leaf_count),
               std::move(cells));
  int furniture_count = 0;
  for (auto& cells : components(masks.furniture))
    add_object(ObjectKind::furniture, SemanticClass::furniture,
               "furniture " + std::to_string(++furniture_count), std::move(cells));
}

// The cells connected (8-neighbours) to (col, row) with its direction bin, not yet taken (taken
// ones are marked -1 in wall_id).
std::vector<Eigen::Vector2i> grow_wall_piece(const SemanticGrid& grid, const Image<int>& bins,
                                             Image<int>& wall_id, int col, int row) {
  const int bin = bins(col, row);
  std::vector<Eigen::Vector2i> cells{{col, row}};
  wall_id(col, row) = -1;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Eigen::Vector2i n = cells[k] + Eigen::Vector2i(dx, dy);
        if (!grid.contains(n) || wall_id(n.x(), n.y()) || bins(n.x(), n.y()) != bin) continue;
        wall_id(n.x(), n.y()) = -1;
        cells.push_back(n);
      }
    }
  }
  return cells;
}

// The straight wall pieces: each cell's wall object id (0: none, -2: a piece too short to be a
// wall) and the ids of the walls.
struct WallPieces {
  Image<int> wall_id;
  std::vector<int> ids;
};

// Walls: straight pieces (cells of one direction, connected) of at least min_wall_length.
WallPieces add_straight_walls(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                              const SemanticGridParams& options,
                              const detail::AddObject& add_object) {
  const Image<int> bins = detail::wall_direction_bins(grid.classes);
  WallPieces walls{Image<int>(grid.width(), grid.height(), 0), {}};
  int wall_count = 0;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const int bin = bins(col, row);
      if (bin < 0 || walls.wall_id(col, row)) continue;
      const std::vector<Eigen::Vector2i> cells =
          grow_wall_piece(grid, bins, walls.wall_id, col, row);
      const double angle = bin * std::numbers::pi / 8;
      const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
      SemanticObject candidate;
      candidate.cells = cells;
      describe_cells(grid, evidence, candidate, false, direction);
      if (candidate.width < options.min_wall_length) {
        for (const auto& c : cells) walls.wall_id(c.x(), c.y()) = -2;  // a leftover
        continue;
      }
      SemanticObject& wall = add_object(ObjectKind::wall, SemanticClass::wall,
                                        "wall " + std::to_string(++wall_count), cells);
      wall.centre = candidate.centre, wall.axis_start = candidate.axis_start;
      wall.axis_end = candidate.axis_end, wall.width = candidate.width;
      walls.ids.push_back(wall.id);
      for (const auto& c : cells) walls.wall_id(c.x(), c.y()) = wall.id;
    }
  }
  return walls;
}

// Leftover wall cells (corners, short pieces) join the wall with the most cells around them.
void join_leftover_wall_cells(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                              const WallPieces& walls) {
  const Image<int>& wall_id = walls.wall_id;
  std::vector<std::vector<Eigen::Vector2i>> extra(grid.objects.size() + 1);
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      if (grid.classes(col, row) != SemanticClass::wall || wall_id(col, row) > 0) continue;
      std::vector<int> votes(grid.objects.size() + 1, 0);
      for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
          const Eigen::Vector2i n(col + dx, row + dy);
          if (grid.contains(n) && wall_id(n.x(), n.y()) > 0) ++votes[wall_id(n.x(), n.y())];
        }
      }
      const auto best = std::max_element(votes.begin(), votes.end());
      if (*best > 0) extra[best - votes.begin()].push_back({col, row});
    }
  }
  for (const int id : walls.ids) {
    SemanticObject& wall = grid.objects[id - 1];
    if (extra[id].empty()) continue;
    wall.cells.insert(wall.cells.end(), extra[id].begin(), extra[id].end());
    describe_cells(grid, evidence, wall, /*keep_axis=*/true);
  }
}

// Detections: their own objects on the cells whose centres their footprint covers.
void add_detections(SemanticGrid& grid, const SemanticGridParams& options,
                    std::span<const ObjectDetection> detections,
                    const detail::AddObject& add_object) {
  for (std::size_t d = 0; d < detections.size(); ++d) {
    const ObjectDetection& det = detections[d];
    const std::string what = "build_semantic_grid: detection " + std::to_string(d) + " (" +
                             (det.name.empty() ? std::string(to_string(det.label)) : det.name) +
                             ")";
    require(det.footprint.size() >= 3,
            what + ": footprint needs >= 3 vertices, got " + std::to_string(det.footprint.size()));
    require(!det.weight || (*det.weight >= 0.0f && *det.weight <= 1.0f),
            what + ": weight must be in [0, 1]");
    std::vector<Eigen::Vector2i> cells;
    for (int row = 0; row < grid.height(); ++row) {
      for (int col = 0; col < grid.width(); ++col) {
        if (point_in_polygon(grid.cell_center({col, row}), det.footprint))
          cells.push_back({col, row});
      }
    }
    if (cells.empty()) continue;  // outside the map or smaller than a cell
    const float w = det.weight.value_or(options.weights.of(det.label));
    for (const auto& c : cells) {
      if (det.label != SemanticClass::unknown) grid.classes(c.x(), c.y()) = det.label;
      if (!std::isnan(w)) grid.weight(c.x(), c.y()) = w;
    }
    SemanticObject& object = add_object(
        ObjectKind::detection, det.label,
        det.name.empty() ? "detection " + std::to_string(d + 1) : det.name, std::move(cells));
    object.z_min = det.z_min, object.z_max = det.z_max;
    object.contour = det.footprint;
  }
}

}  // namespace

void TraversabilityWeights::validate() const {
  for (std::size_t c = 0; c < by_class.size(); ++c) {
    const float w = by_class[c];
    require(std::isnan(w) || (w >= 0.0f && w <= 1.0f),
            "TraversabilityWeights: weight of class " + std::string(kSemanticClassNames[c]) +
                " must be in [0, 1] or NaN (unknown), got " + std::to_string(w));
  }
  require(unclassified_obstacle >= 0.0f && unclassified_obstacle <= 1.0f,
          "TraversabilityWeights: unclassified_obstacle must be in [0, 1], got " +
              std::to_string(unclassified_obstacle));
}

void SemanticGridParams::validate() const {
  auto positive = [](double v, const char* name) {
    require(std::isfinite(v) && v > 0, std::string("SemanticGridParams: ") + name +
                                           " must be positive, got " + std::to_string(v));
  };
  positive(resolution, "resolution");
  positive(floor_tolerance, "floor_tolerance");
  positive(band_max, "band_max");
  require(band_min >= 0 && band_min < band_max,
          "SemanticGridParams: need 0 <= band_min < band_max, got " + std::to_string(band_min) +
              " and " + std::to_string(band_max));
  require(min_obstacle_points >= 1 && min_floor_points >= 1 && min_obstacle_views >= 1,
          "SemanticGridParams: min_obstacle_points, min_obstacle_views and min_floor_points must "
          "be >= 1");
  require(margin >= 0, "SemanticGridParams: margin must be >= 0");
  require(std::isfinite(furniture_max_extent) && furniture_max_extent >= 0 &&
              std::isfinite(furniture_max_height) && furniture_max_height > 0,
          "SemanticGridParams: furniture_max_extent must be >= 0 and furniture_max_height > 0");
  require(std::isfinite(furniture_max_depth) && furniture_max_depth >= 0,
          "SemanticGridParams: furniture_max_depth must be >= 0");
  require(std::isfinite(max_wall_thickness) && max_wall_thickness >= 0 &&
              std::isfinite(max_floor_shadow) && max_floor_shadow >= 0 &&
              std::isfinite(max_floor_hole) && max_floor_hole >= 0,
          "SemanticGridParams: max_wall_thickness, max_floor_shadow and max_floor_hole must be "
          ">= 0");
  require(std::isfinite(max_unseen_wall_gap) && max_unseen_wall_gap >= 0,
          "SemanticGridParams: max_unseen_wall_gap must be >= 0");
  require(free_space_ray_stride >= 0, "SemanticGridParams: free_space_ray_stride must be >= 0");
  positive(free_space_slab, "free_space_slab");
  positive(furniture_join_gap, "furniture_join_gap");
  require(std::isfinite(phantom_pass_ratio) && phantom_pass_ratio >= 0,
          "SemanticGridParams: phantom_pass_ratio must be >= 0");
  require(std::isfinite(phantom_margin) && phantom_margin >= 0,
          "SemanticGridParams: phantom_margin must be >= 0");
  require(std::isfinite(free_space_end_margin) && free_space_end_margin >= 0,
          "SemanticGridParams: free_space_end_margin must be >= 0");
  require(std::isfinite(seen_through_wall_range) && seen_through_wall_range >= 0,
          "SemanticGridParams: seen_through_wall_range must be >= 0");
  require(std::isfinite(face_spill_ratio) && face_spill_ratio >= 0,
          "SemanticGridParams: face_spill_ratio must be >= 0");
  require(min_door_width > 0 && min_door_width < max_door_width,
          "SemanticGridParams: need 0 < min_door_width < max_door_width");
  weights.validate();
}

std::string_view to_string(ObjectKind kind) {
  switch (kind) {
    case ObjectKind::wall:
      return "wall";
    case ObjectKind::doorway:
      return "doorway";
    case ObjectKind::door_leaf:
      return "door";
    case ObjectKind::furniture:
      return "furniture";
    case ObjectKind::detection:
      return "detection";
  }
  return "?";
}

const SemanticObject& SemanticGrid::object(int id) const {
  require(id >= 1 && id <= static_cast<int>(objects.size()),
          "SemanticGrid: no object " + std::to_string(id) + " (the map has " +
              std::to_string(objects.size()) + ")");
  return objects[static_cast<std::size_t>(id - 1)];
}

namespace {

// Origins, when given, must name every view the points' ids refer to.
void check_view_origins(std::span<const std::uint32_t> view_ids,
                        std::span<const Eigen::Vector3d> view_origins) {
  if (view_origins.empty()) return;
  const std::uint32_t last =
      view_ids.empty() ? 0 : *std::max_element(view_ids.begin(), view_ids.end());
  require(!view_ids.empty() && last < view_origins.size(),
          "build_semantic_grid: " + std::to_string(view_origins.size()) + " view origins for " +
              (view_ids.empty() ? std::string("points without view ids")
                                : "views up to " + std::to_string(last)));
}

// Whole cells in `metres` at `resolution`.
int whole_cells(double metres, double resolution) {
  return static_cast<int>(std::floor(metres / resolution + 1e-9));
}

// The walls seen from one side: their hidden backs and corners, then the wall lines and room
// corners hidden behind furniture, the wall lines across what no view saw, then the backs of those
// lines' faces; `thickness` cells thick (the two-sided walls'; 0: unknown, no backs).
void complete_one_sided_walls(SemanticGrid& grid, const SemanticGridParams& options, int thickness,
                              int max_wall, ObstacleMasks& masks) {
  const auto cells = [&](double metres) { return whole_cells(metres, options.resolution); };
  detail::back_one_sided_walls(grid, thickness, max_wall, options.weights.of(SemanticClass::wall));
  if (options.back_one_sided_walls)
    detail::fill_wall_corners(grid, thickness, options.weights.of(SemanticClass::wall));
  // Last: the backs and corners above make the wall lines whose hidden stretches it joins.
  if (options.back_one_sided_walls && max_wall > 0 && options.furniture_max_extent > 0) {
    const int gap = cells(options.furniture_max_extent);
    const float wall = options.weights.of(SemanticClass::wall);
    grid.inferred.furniture_in_wall_lines =
        detail::wall_lines_behind_furniture(grid, gap, max_wall + 1, wall, masks.furniture);
    grid.inferred.wall_corners_behind_furniture =
        detail::wall_corners_behind_furniture(grid, gap, max_wall + 1, wall);
  }
  if (options.back_one_sided_walls && max_wall > 0 && options.max_unseen_wall_gap > 0) {
    grid.inferred.wall_cells_across_unseen =
        detail::wall_lines_across_unseen(grid, cells(options.max_unseen_wall_gap), max_wall + 1,
                                         options.weights.of(SemanticClass::wall));
  }
  // The lines' faces have their backs too, where the backs beside them were too short to bridge
  // (a cell no view saw, or a speck seen, ends a back's row).
  detail::back_one_sided_walls(grid, thickness, max_wall, options.weights.of(SemanticClass::wall));
  if (thickness > 0) grid.inferred.wall_thickness = thickness * options.resolution;
}

// The floor no view saw: under the rays that crossed it low, in thin shadows and in holes of the
// seen floor; no fill takes a drop (the views saw below the floor in its piece of unseen cells).
// Returns the drops.
Image<std::uint8_t> fill_unseen_floor(SemanticGrid& grid, const Image<std::uint8_t>& below_floor,
                                      const detail::BandFreeSpace* free_space,
                                      const SemanticGridParams& options) {
  const float weight = options.weights.of(SemanticClass::floor);
  const Image<std::uint8_t> drops = drop_regions(grid, below_floor);
  // Before the floor's shadows and holes, which the floor seen through may close.
  if (free_space && options.floor_seen_through)
    grid.inferred.floor_seen_through = detail::floor_seen_through(grid, *free_space, drops, weight);
  if (options.max_floor_shadow > 0) {
    fill_unobserved_runs(grid, SemanticClass::floor,
                         whole_cells(options.max_floor_shadow, options.resolution), weight, &drops);
  }
  if (options.max_floor_hole > 0) {
    fill_floor_holes(
        grid, options.max_floor_hole, weight, drops,
        [&](std::span<const Eigen::Vector2i> hole) { return enclosed_by_floor(grid, hole); });
  }
  return drops;
}

// The cells no view saw that the seen ones imply (walls' insides and hidden backs, furniture
// pockets, floor shadows), and the wall faces placed on the wall points.
void complete_hidden_cells(SemanticGrid& grid, const detail::BandPointIndex& wall_points,
                           const Image<std::uint8_t>& below_floor,
                           const detail::BandFreeSpace* free_space,
                           const SemanticGridParams& options, ObstacleMasks& masks) {
  const auto cells = [&](double metres) { return whole_cells(metres, options.resolution); };
  const bool fronts = options.furniture_max_depth > 0 && options.furniture_max_extent > 0;
  // The walls' thickness across their unseen insides: an unseen run between a furniture-sized face
  // and a wall, deeper than a wall's inside (by a cell, for noise), is what a cabinet hid, and the
  // insides' fill leaves it to the fronts.
  const int max_wall = cells(options.max_wall_thickness);
  // First: a speck inside a wall would stop every fill across the wall below.
  if (max_wall > 0) {
    grid.inferred.wall_specks = detail::furniture_specks_in_walls(
        grid, max_wall, options.weights.of(SemanticClass::wall), masks.furniture);
  }
  const int across =
      max_wall > 0 ? detail::two_sided_wall_thickness(grid, max_wall, kMinTwoSidedWallCells, true)
                   : 0;
  const int min_pocket = across > 0 ? std::min(across - 1, max_wall) : max_wall;
  std::optional<Image<std::uint8_t>> pockets;
  if (fronts && min_pocket < max_wall) {
    pockets = detail::front_pockets(grid, options.furniture_max_extent,
                                    options.max_furniture_fill_area, min_pocket, max_wall);
  }
  if (max_wall > 0) {
    fill_unobserved_runs(grid, SemanticClass::wall, max_wall,
                         options.weights.of(SemanticClass::wall), pockets ? &*pockets : nullptr);
  }
  // After the furniture fills (no hull should span a front and its pocket) and the walls' insides
  // (which are no pockets).
  if (fronts) {
    // A wall's inside, which a pocket reaching a far face stops short of: unknown without the
    // walls' thickness.
    const int inside = across > 0 ? min_pocket : 0;
    const detail::FrontsFound apart = detail::fronts_against_walls(
        grid, options.furniture_max_extent, options.max_furniture_fill_area, min_pocket, inside,
        cells(options.furniture_max_depth), options.weights, masks.furniture);
    const detail::FrontsFound joined = detail::joined_fronts_against_walls(
        grid, options.furniture_max_extent, options.max_furniture_fill_area, inside,
        cells(options.furniture_max_depth), options.weights, masks.furniture);
    // After the other front rules, whose pockets are closed (a cabinet's pocket here is open
    // at the back, which it closes with the wall line).
    const int cabinets = detail::cabinets_before_hidden_walls(
        grid,
        {cells(options.furniture_max_extent), min_pocket, cells(options.furniture_max_depth),
         options.max_furniture_fill_area},
        options.weights, masks.furniture);
    grid.inferred.furniture_fronts = apart.fronts + joined.fronts + cabinets;
    grid.inferred.wall_insides_behind_fronts = apart.wall_inside_cells + joined.wall_inside_cells;
    // Last: the fronts above are among the faces whose hidden backs it fills.
    grid.inferred.furniture_pockets = detail::pockets_behind_furniture(
        grid, options.furniture_max_extent, options.max_furniture_fill_area,
        cells(options.furniture_max_depth), options.weights.of(SemanticClass::furniture),
        masks.furniture);
  }
  const Image<std::uint8_t> drops = fill_unseen_floor(grid, below_floor, free_space, options);
  // The walls' thickness is measured before their faces are placed: a wall's two faces, seen
  // from views whose poses differ by a centimetre or two, lose a row to the placement often
  // enough to move the median (0.15 -> 0.10 m on a survey with the SLAM's poses).
  const int thickness =
      options.back_one_sided_walls && max_wall > 0
          ? detail::two_sided_wall_thickness(grid, max_wall, kMinTwoSidedWallCells)
          : 0;
  // After the walls' thickness: runs from floor inferred beside a wall measure the noise of its
  // face too (on held-out seed 25 a shadow filled beside a wall took the walls 0.2 -> 0.25 m).
  if (options.max_floor_hole > 0) {
    fill_floor_holes(
        grid, options.max_floor_hole, options.weights.of(SemanticClass::floor), drops,
        [&](std::span<const Eigen::Vector2i> hole) { return between_floor_and_walls(grid, hole); });
  }
  // After the fronts (a front's face moved in would take a row from its pocket), before the
  // walls' hidden backs (which start at the faces).
  if (options.place_wall_faces) {
    detail::place_wall_faces(grid, wall_points, options.weights, masks.furniture);
  }
  complete_one_sided_walls(grid, options, thickness, max_wall, masks);
}

// Door leaves one cell thick where their faces say so (before they become objects).
void place_leaf_faces(SemanticGrid& grid, const Image<CellEvidence>& evidence,
                      std::span<const Eigen::Vector3d> points,
                      std::span<const SemanticClass> labels, const SemanticGridParams& options,
                      ObstacleMasks& masks) {
  if (!options.place_leaf_faces) return;
  const detail::BandPointIndex door_points(grid, points, labels, options, SemanticClass::door);
  detail::place_leaf_faces(grid, door_points, floor_seen(evidence, options), options.weights,
                           masks.leaf);
}

}  // namespace

SemanticGrid build_semantic_grid(std::span<const Eigen::Vector3d> points,
                                 std::span<const SemanticClass> labels,
                                 const SemanticGridParams& options,
                                 std::span<const ObjectDetection> detections,
                                 std::span<const std::uint32_t> view_ids,
                                 std::span<const Eigen::Vector3d> view_origins) {
  check_inputs(points, labels, options);
  require(view_ids.empty() || view_ids.size() == points.size(),
          "build_semantic_grid: " + std::to_string(view_ids.size()) + " view ids for " +
              std::to_string(points.size()) + " points");
  check_view_origins(view_ids, view_origins);
  SemanticGrid grid = empty_grid(points, labels, options);
  std::optional<detail::BandFreeSpace> free_space;
  if (options.free_space_ray_stride > 0 && !view_origins.empty())
    free_space.emplace(detail::carve_band(grid, points, view_ids, view_origins, options));
  const std::vector<std::uint8_t> phantom =
      free_space && options.phantom_pass_ratio > 0
          ? detail::phantom_points(grid, points, labels, *free_space, options)
          : std::vector<std::uint8_t>();
  const Image<CellEvidence> evidence =
      gather_evidence(grid, points, labels, view_ids, phantom, options);
  // Fewer views than min_obstacle_views (one scan) ask for what they can give.
  SemanticGridParams cell_options = options;
  cell_options.min_obstacle_views = std::min(options.min_obstacle_views, count_views(view_ids));
  ObstacleMasks masks = classify_cells(grid, evidence, cell_options);
  if (free_space) {
    const Image<std::uint8_t> seen_floor = floor_seen(evidence, options);
    raised_walls_to_unclassified(grid, evidence, *free_space,
                                 options.weights.unclassified_obstacle);
    if (options.seen_through_wall_range > 0) {
      detail::free_seen_through_walls(
          grid, *free_space,
          detail::nearest_wall_ranges(grid, points, labels, view_ids, view_origins, options),
          seen_floor, masks.furniture, options);
    }
    if (options.face_spill_ratio > 0) {
      free_face_spill(grid, evidence, *free_space, seen_floor, options.face_spill_ratio,
                      options.weights.of(SemanticClass::floor));
    }
  }
  if (options.spill_margin > 0) remove_spill(grid, evidence, options, masks.leaf, masks.furniture);
  if (options.remove_isolated_obstacles)
    remove_isolated_obstacles(grid, evidence, options, masks.leaf, masks.furniture);
  const detail::BandPointIndex wall_points(grid, points, labels, options);

  const detail::AddObject add_object = [&](ObjectKind kind, SemanticClass label,
                                           const std::string& name,
                                           std::vector<Eigen::Vector2i> cells) -> SemanticObject& {
    return append_object(grid, evidence, kind, label, name, std::move(cells));
  };
  if (options.max_furniture_fill_area > 0 && options.furniture_max_extent > 0)
    unclassified_to_furniture(grid, evidence, options, masks.furniture);
  if (options.max_furniture_fill_area > 0) {
    const Image<std::uint8_t> marked = masks.furniture;  // before the fill
    fill_furniture(grid, evidence, free_space ? &*free_space : nullptr, masks.furniture,
                   options.furniture_join_gap, options.max_furniture_fill_area,
                   options.weights.of(SemanticClass::furniture));
    if (free_space) tables_on_legs(grid, evidence, *free_space, options, marked, masks.furniture);
  }
  if (options.max_furniture_fill_area > 0 && options.weights.unclassified_obstacle == 0.0f)
    fill_enclosed_by_unclassified(grid, options.max_furniture_fill_area, 0.0f);
  complete_hidden_cells(grid, wall_points, below_floor_seen(evidence),
                        free_space ? &*free_space : nullptr, options, masks);
  place_leaf_faces(grid, evidence, points, labels, options, masks);
  add_obstacle_objects(masks, add_object);
  const WallPieces walls = add_straight_walls(grid, evidence, options, add_object);
  join_leftover_wall_cells(grid, evidence, walls);
  detail::add_gap_doorways(grid, options, wall_points, walls.ids, add_object);
  add_detections(grid, options, detections, add_object);

  for (const SemanticObject& object : grid.objects) {
    for (const auto& c : object.cells) grid.cell_objects(c.x(), c.y()).push_back(object.id);
  }
  return grid;
}

// ---- Exports ---------------------------------------------------------------------------------

MapDescription describe(const SemanticGrid& grid) {
  MapDescription d;
  d.resolution = grid.resolution;
  d.origin = grid.origin;
  d.width = grid.width(), d.height = grid.height();
  d.floor_z = grid.floor_z;
  d.ceiling_z = grid.ceiling_z;
  d.inferred = grid.inferred;
  for (int c = 0; c < kSemanticClassCount; ++c)
    d.class_weights.emplace_back(std::string(kSemanticClassNames[c]), grid.weights.by_class[c]);
  d.class_weights.emplace_back("unclassified obstacle", grid.weights.unclassified_obstacle);
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      if (std::isnan(grid.weight(col, row)))
        ++d.unobserved_cells;
      else
        ++d.cells_per_class[index_of(grid.classes(col, row))];
    }
  }
  for (const SemanticObject& o : grid.objects) {
    d.objects.push_back({o.id, std::string(to_string(o.kind)), std::string(to_string(o.label)),
                         o.name, o.contour, o.z_min, o.z_max, o.area, o.width, o.centre,
                         o.axis_start, o.axis_end, static_cast<int>(o.cells.size())});
  }
  return d;
}

Rgb8 class_colour(SemanticClass c) {
  switch (c) {
    case SemanticClass::floor:
      return {245, 245, 232};
    case SemanticClass::wall:
      return {25, 25, 25};
    case SemanticClass::ceiling:
      return {120, 180, 240};
    case SemanticClass::door:
      return {235, 140, 20};
    case SemanticClass::furniture:
      return {140, 70, 170};
    case SemanticClass::unknown:
      return {210, 40, 40};  // an unclassified obstacle
  }
  return {0, 0, 0};
}

MapPicture render_map(const SemanticGrid& grid, int pixels_per_cell) {
  require(pixels_per_cell >= 1 && pixels_per_cell <= 32,
          "render_map: pixels_per_cell must be in 1..32, got " + std::to_string(pixels_per_cell));
  struct Entry {
    Rgb8 colour;
    std::string text;
  };
  auto weight_text = [](float w) {
    if (std::isnan(w)) return std::string("unknown");
    std::ostringstream s;
    s.precision(2);
    s << w;
    return s.str();
  };
  const std::vector<SemanticClass> shown = {SemanticClass::floor, SemanticClass::door,
                                            SemanticClass::wall, SemanticClass::furniture,
                                            SemanticClass::unknown};
  std::vector<Entry> legend;
  for (const SemanticClass c : shown) {
    const std::string name =
        c == SemanticClass::unknown ? "other obstacle" : std::string(to_string(c));
    const float w =
        c == SemanticClass::unknown ? grid.weights.unclassified_obstacle : grid.weights.of(c);
    legend.push_back({class_colour(c), name + "  w=" + weight_text(w)});
  }
  legend.push_back({kUnobservedColour, "unobserved"});

  constexpr int kLine = 16;
  const int map_w = grid.width() * pixels_per_cell, map_h = grid.height() * pixels_per_cell;
  const int width = std::max(map_w, 190);
  const int height = map_h + 6 + kLine * static_cast<int>(legend.size());
  cv::Mat picture(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Rgb8 c = std::isnan(grid.weight(col, row)) ? kUnobservedColour
                                                       : class_colour(grid.classes(col, row));
      cv::rectangle(
          picture,
          cv::Rect(col * pixels_per_cell, row * pixels_per_cell, pixels_per_cell, pixels_per_cell),
          cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    }
  }
  for (std::size_t i = 0; i < legend.size(); ++i) {
    const int y = map_h + 6 + kLine * static_cast<int>(i);
    const Rgb8& c = legend[i].colour;
    cv::rectangle(picture, cv::Rect(4, y, 12, 12), cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
    cv::rectangle(picture, cv::Rect(4, y, 12, 12), cv::Scalar(0, 0, 0), 1);
    cv::putText(picture, legend[i].text, cv::Point(22, y + 11), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }

  MapPicture out;
  out.pixels_per_cell = pixels_per_cell;
  out.map_width = grid.width(), out.map_height = grid.height();
  out.image = RgbImage(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const cv::Vec3b& v = picture.at<cv::Vec3b>(y, x);
      out.image(x, y) = {v[0], v[1], v[2]};  // the channels were drawn in RGB order
    }
  }
  return out;
}

OccupancyGrid to_occupancy_grid(const SemanticGrid& grid) {
  OccupancyGrid out;
  out.resolution = grid.resolution;
  out.origin = Eigen::Vector3d(grid.origin.x(), grid.origin.y(), 0.0);
  out.cells = Image<CellState>(grid.width(), grid.height(), CellState::unknown);
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const float w = grid.weight(col, row);
      if (!std::isnan(w)) out.cells(col, row) = w > 0 ? CellState::free : CellState::occupied;
    }
  }
  return out;
}

Image<std::uint8_t> to_costmap(const SemanticGrid& grid) {
  Image<std::uint8_t> out(grid.width(), grid.height(), 255);
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const float w = grid.weight(col, row);
      if (!std::isnan(w)) out(col, row) = static_cast<std::uint8_t>(std::lround(254.0 * (1.0 - w)));
    }
  }
  return out;
}

}  // namespace kartograf::semantic
