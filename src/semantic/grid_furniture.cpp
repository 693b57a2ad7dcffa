#include "semantic/grid_furniture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <span>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "semantic/grid_cells.hpp"

namespace kartograf::semantic::detail {
namespace {

bool is_wall(const SemanticGrid& grid, int col, int row) {
  return seen_as(grid, {col, row}, SemanticClass::wall);
}

// Whether a seen floor cell lies within `cells` steps of `out` beyond c.
bool floor_within(const SemanticGrid& grid, const Eigen::Vector2i& c, const Eigen::Vector2i& out,
                  int cells) {
  for (int k = 1; k <= cells; ++k)
    if (seen_as(grid, c + k * out, SemanticClass::floor)) return true;
  return false;
}

// Unseen cells on a row or column run of unseen cells with wall cells at both ends, longer than
// min_cells (a wall's inside) and at most max_cells: what lies between two faces. With
// `facing_the_room`, only runs one of whose ends has floor within 3 cells beyond it: a front the
// room saw, with the pocket it hid behind it. An unseen stretch of a wall's own line, between two
// of its pieces, has the wall running on beyond both ends (survey seed 4: a 2.15 m piece of the
// wall between two rooms had become a cabinet's front across such a gap, and the rooms merged).
cv::Mat pockets_between_walls(const SemanticGrid& grid, int min_cells, int max_cells,
                              bool facing_the_room) {
  cv::Mat pockets = cv::Mat::zeros(grid.height(), grid.width(), CV_8U);
  const auto wall_end = [&](const Eigen::Vector2i& c) { return is_wall(grid, c.x(), c.y()); };
  const auto accept = [&](const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
    const Eigen::Vector2i step = (b - a).cwiseSign();
    return !facing_the_room || floor_within(grid, a, -step, 3) || floor_within(grid, b, step, 3);
  };
  for (const Eigen::Vector2i& k :
       unobserved_runs_between(grid, wall_end, min_cells, max_cells, accept))
    pockets.at<std::uint8_t>(k.y(), k.x()) = 255;
  return pockets;
}

// Connected pieces (8-neighbours) of a mask: a label image and each piece's cells.
struct Pieces {
  cv::Mat labels;
  std::vector<std::vector<cv::Point>> cells;  // index = label; 0 is the background
};

// The cells seen as `wanted`, as a mask (255).
cv::Mat seen_mask(const SemanticGrid& grid, SemanticClass wanted) {
  cv::Mat mask(grid.height(), grid.width(), CV_8U);
  for (int row = 0; row < grid.height(); ++row)
    for (int col = 0; col < grid.width(); ++col)
      mask.at<std::uint8_t>(row, col) = seen_as(grid, {col, row}, wanted) ? 255 : 0;
  return mask;
}

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
    for (const Eigen::Vector2i& d : kFourNeighbours) {
      if (seen_as(grid, Eigen::Vector2i(c.x, c.y) + d, SemanticClass::floor)) {
        ++facing;
        break;
      }
    }
  }
  return 2 * facing >= cells.size();
}

// The 4-neighbours of cells that lie in the grid.
template <typename Visit>
void for_each_neighbour(const SemanticGrid& grid, const std::vector<cv::Point>& cells,
                        Visit&& visit) {
  for (const cv::Point& c : cells) {
    for (const Eigen::Vector2i& d : kFourNeighbours) {
      const cv::Point n = c + cv::Point(d.x(), d.y());
      if (grid.contains({n.x, n.y})) visit(n);
    }
  }
}

// The wall pieces (labels of `wall_labels`) a pocket touches.
std::set<int> walls_around(const SemanticGrid& grid, const cv::Mat& wall_labels,
                           const std::vector<cv::Point>& cells) {
  std::set<int> walls;
  for_each_neighbour(grid, cells, [&](const cv::Point& n) {
    if (const int w = wall_labels.at<int>(n.y, n.x); w > 0) walls.insert(w);
  });
  return walls;
}

bool beside_door(const SemanticGrid& grid, const std::vector<cv::Point>& cells) {
  std::vector<Eigen::Vector2i> at;
  at.reserve(cells.size());
  for (const cv::Point& c : cells) at.emplace_back(c.x, c.y);
  return detail::beside_door(grid, at);
}

// Cells of a joined front's pocket, each way (0.15 m at 5 cm cells).
constexpr int kMinPocketCells = 3;

// One side of a pocket's box: the line of cells just outside it, from `from` in steps of `along`
// (`length` cells), and the step out of the box.
struct BoxSide {
  cv::Point from, along, out;
  int length;
};

std::array<BoxSide, 4> sides_of(const cv::Rect& box) {
  const int x0 = box.x, y0 = box.y, x1 = box.x + box.width - 1, y1 = box.y + box.height - 1;
  return {BoxSide{{x0 - 1, y0}, {0, 1}, {-1, 0}, box.height},
          BoxSide{{x1 + 1, y0}, {0, 1}, {1, 0}, box.height},
          BoxSide{{x0, y0 - 1}, {1, 0}, {0, -1}, box.width},
          BoxSide{{x0, y1 + 1}, {1, 0}, {0, 1}, box.width}};
}

// Whether the side's line goes on as wall past both of the box's corners (1-2 cells beyond them):
// the wall behind a cabinet runs on; its sides and front stop at its corners.
bool runs_on_past_corners(const SemanticGrid& grid, const BoxSide& side) {
  const auto wall_within = [&](cv::Point corner, cv::Point step) {
    for (int k = 1; k <= 2; ++k)
      if (is_wall(grid, (corner + k * step).x, (corner + k * step).y)) return true;
    return false;
  };
  const cv::Point first = side.from - side.along, last = side.from + side.length * side.along;
  return wall_within(first, -side.along) && wall_within(last, side.along);
}

// Whether most cells of a side's line have floor within 3 cells beyond it: a front faces the room.
bool floor_beyond(const SemanticGrid& grid, const BoxSide& side) {
  int facing = 0;
  for (int k = 0; k < side.length; ++k) {
    for (int d = 1; d <= 3; ++d) {
      const cv::Point c = side.from + k * side.along + d * side.out;
      if (seen_as(grid, {c.x, c.y}, SemanticClass::floor)) {
        ++facing;
        break;
      }
    }
  }
  return 2 * facing > side.length;
}

// A cabinet's front and sides joined to the wall behind it: their wall cells, and the step from
// the pocket towards the wall behind.
struct JoinedFront {
  std::vector<cv::Point> cells;
  Eigen::Vector2i back;
};

// The wall cells around a pocket but for its back: the front and sides of a cabinet whose faces
// the views took for walls, joined to the wall behind it. Empty unless exactly one side of the
// pocket's box runs on as a wall past its corners, and the side opposite faces floor.
JoinedFront front_and_sides(const SemanticGrid& grid, const std::vector<cv::Point>& pocket) {
  const cv::Rect box = cv::boundingRect(pocket);
  // A cabinet's inside is a few cells each way; a sliver of unseen cells in a noisy wall is not.
  if (box.width < kMinPocketCells || box.height < kMinPocketCells) return {};
  const std::array<BoxSide, 4> sides = sides_of(box);
  int back = -1;
  for (int s = 0; s < 4; ++s) {
    if (!runs_on_past_corners(grid, sides[static_cast<std::size_t>(s)])) continue;
    if (back >= 0) return {};
    back = s;
  }
  if (back < 0 || !floor_beyond(grid, sides[static_cast<std::size_t>(back ^ 1)])) return {};
  // Two cells out on the front and the sides (a face's noise spills into the cell in front of it);
  // nothing from the back's line on.
  int x0 = box.x - 2, x1 = box.x + box.width + 1, y0 = box.y - 2, y1 = box.y + box.height + 1;
  if (back == 0) x0 = box.x;
  if (back == 1) x1 = box.x + box.width - 1;
  if (back == 2) y0 = box.y;
  if (back == 3) y1 = box.y + box.height - 1;
  const cv::Point out = sides[static_cast<std::size_t>(back)].out;
  JoinedFront joined{{}, Eigen::Vector2i(out.x, out.y)};
  for (int row = y0; row <= y1; ++row)
    for (int col = x0; col <= x1; ++col)
      if (is_wall(grid, col, row)) joined.cells.push_back({col, row});
  return joined;
}

// How far a wall's far face runs on either way along its line from a cell of it [m]: farther than
// a wall is thick, so the side of a cabinet that joins a wall (wall cells with floor beyond them
// too) is no far face.
constexpr double kFarFaceRunsOn = 0.4;

// Whether wall cell c lies in a wall that the rooms on both its sides saw: across it, along a row
// or a column, at most `max_across` wall cells with seen floor just beyond both ends, in a line
// that runs on along the other axis for kFarFaceRunsOn or more. A cabinet's front is as thin but
// has the pocket its top hid behind it; a narrow front's corner has floor beyond both of the
// front's ends, but no line across it.
bool between_rooms(const SemanticGrid& grid, const Eigen::Vector2i& c, int max_across) {
  const int along = static_cast<int>(std::ceil(kFarFaceRunsOn / grid.resolution));
  for (const Eigen::Vector2i& across : {Eigen::Vector2i(1, 0), Eigen::Vector2i(0, 1)}) {
    if (!floor_beyond_both_faces(grid, c, across, max_across)) continue;
    const Eigen::Vector2i line(across.y(), across.x());
    if (wall_run(grid, c, line, along) + wall_run(grid, c, -line, along) + 1 >= along) return true;
  }
  return false;
}

// Whether a piece of wall cells holds a wall between two rooms (`between_rooms`) for
// kFarFaceRunsOn or more. A cabinet's front and sides have its pocket behind them; on survey seed
// 18 a wall between two rooms, seen from both between two cabinets standing back to back against
// it, had joined the front of one into a furniture-sized piece, become furniture, and the rooms
// merged.
bool holds_wall_between_rooms(const SemanticGrid& grid, const std::vector<cv::Point>& cells,
                              int max_across) {
  const int enough = static_cast<int>(std::ceil(kFarFaceRunsOn / grid.resolution));
  int between = 0;
  for (const cv::Point& c : cells)
    if (between_rooms(grid, {c.x, c.y}, max_across) && ++between >= enough) return true;
  return false;
}

// The wall pieces of the grid (8-neighbours) and which are longer than furniture.
struct WallPieces {
  Pieces pieces;
  std::vector<bool> long_wall, front_like;  // by label; front_like: furniture sized, facing floor
};

// The most wall cells across a wall between two rooms, from the cells of a wall's inside (its
// thickness less a cell): the thickness, and a cell of depth noise.
int max_wall_across(int inside_cells) {
  return inside_cells + 2;
}

// `max_across`: the most cells across a wall between two rooms, which no front holds (0: none).
WallPieces wall_pieces(const SemanticGrid& grid, double max_extent, double max_area,
                       int max_across) {
  WallPieces w{pieces_of(seen_mask(grid, SemanticClass::wall)), {}, {}};
  w.long_wall.resize(w.pieces.cells.size());
  w.front_like.resize(w.pieces.cells.size());
  for (std::size_t k = 1; k < w.pieces.cells.size(); ++k) {
    const std::vector<cv::Point>& cells = w.pieces.cells[k];
    const bool sized = furniture_sized(cells, grid.resolution, max_extent, max_area);
    w.front_like[k] =
        sized && faces_floor(grid, cells) && !holds_wall_between_rooms(grid, cells, max_across);
    w.long_wall[k] = !sized;
  }
  return w;
}

// A furniture-sized pocket beside a longer wall and no door; `beside` gets the wall pieces it
// touches.
bool backed_pocket(const SemanticGrid& grid, const WallPieces& walls,
                   const std::vector<cv::Point>& pocket, double max_extent, double max_area,
                   std::set<int>& beside) {
  if (!furniture_sized(pocket, grid.resolution, max_extent, max_area)) return false;
  if (beside_door(grid, pocket)) return false;
  beside = walls_around(grid, walls.pieces.labels, pocket);
  return std::any_of(beside.begin(), beside.end(), [&](int w) { return walls.long_wall[w]; });
}

// Whether a cell of a longer wall's face whose other side the room saw (floor within 2 cells beyond
// it, the line running on either way) lies within `inside` cells of unseen cell c along `step`.
bool far_face_within(const SemanticGrid& grid, const WallPieces& walls, const Eigen::Vector2i& c,
                     const Eigen::Vector2i& step, int inside) {
  const int runs_on = static_cast<int>(std::ceil(kFarFaceRunsOn / grid.resolution));
  const Eigen::Vector2i along(step.y(), step.x());
  for (int k = 1; k <= inside; ++k) {
    const Eigen::Vector2i n = c + k * step;
    if (unobserved(grid, n)) continue;
    return is_wall(grid, n.x(), n.y()) &&
           walls.long_wall[static_cast<std::size_t>(walls.pieces.labels.at<int>(n.y(), n.x()))] &&
           floor_within(grid, n, step, 2) && wall_run(grid, n, along, runs_on) >= runs_on &&
           wall_run(grid, n, -along, runs_on) >= runs_on;
  }
  return false;
}

// Whether unseen cell c lies in the inside of a longer wall seen from its far side only, towards
// one of `steps`. A cabinet against a wall hides the wall's near face, and the pocket between the
// cabinet's front and the far face spans the wall's inside too: that is wall, not the cabinet.
bool inside_a_wall_seen_from_beyond(const SemanticGrid& grid, const WallPieces& walls,
                                    const cv::Point& c, int inside,
                                    std::span<const Eigen::Vector2i> steps) {
  return std::any_of(steps.begin(), steps.end(), [&](const Eigen::Vector2i& step) {
    return far_face_within(grid, walls, {c.x, c.y}, step, inside);
  });
}

void mark_furniture(SemanticGrid& grid, const std::vector<cv::Point>& cells, float weight,
                    Image<std::uint8_t>& furniture) {
  for (const cv::Point& c : cells) {
    grid.classes(c.x, c.y) = SemanticClass::furniture;
    grid.weight(c.x, c.y) = weight;
    furniture(c.x, c.y) = 1;
  }
}

// A cabinet's pocket split into its own cells and the inside of the wall it stands against.
struct PocketSplit {
  std::vector<cv::Point> furniture;
  std::vector<Eigen::Vector2i> wall_inside;

  void add(const SemanticGrid& grid, const WallPieces& walls, const std::vector<cv::Point>& pocket,
           int inside_cells, std::span<const Eigen::Vector2i> towards_wall) {
    for (const cv::Point& c : pocket) {
      if (inside_a_wall_seen_from_beyond(grid, walls, c, inside_cells, towards_wall))
        wall_inside.emplace_back(c.x, c.y);
      else
        furniture.push_back(c);
    }
  }
  void mark(SemanticGrid& grid, const TraversabilityWeights& weights,
            Image<std::uint8_t>& mask) const {
    mark_furniture(grid, furniture, weights.of(SemanticClass::furniture), mask);
    set_class(grid, wall_inside, SemanticClass::wall, weights.of(SemanticClass::wall));
  }
};

}  // namespace

FrontsFound fronts_against_walls(SemanticGrid& grid, double max_extent, double max_area,
                                 int min_depth_cells, int inside_cells, int max_depth_cells,
                                 const TraversabilityWeights& weights,
                                 Image<std::uint8_t>& furniture) {
  const WallPieces walls =
      wall_pieces(grid, max_extent, max_area, max_wall_across(min_depth_cells));
  const Pieces pockets =
      pieces_of(pockets_between_walls(grid, min_depth_cells, max_depth_cells, true));
  int fronts = 0;
  PocketSplit split;
  for (std::size_t p = 1; p < pockets.cells.size(); ++p) {
    std::set<int> beside;
    if (!backed_pocket(grid, walls, pockets.cells[p], max_extent, max_area, beside)) continue;
    if (std::none_of(beside.begin(), beside.end(), [&](int w) { return walls.front_like[w]; }))
      continue;
    ++fronts;
    split.add(grid, walls, pockets.cells[p], inside_cells, kFourNeighbours);
    for (const int w : beside) {
      if (walls.front_like[w])
        split.furniture.insert(split.furniture.end(), walls.pieces.cells[w].begin(),
                               walls.pieces.cells[w].end());
    }
  }
  split.mark(grid, weights, furniture);
  return {fronts, static_cast<int>(split.wall_inside.size())};
}

FrontsFound joined_fronts_against_walls(SemanticGrid& grid, double max_extent, double max_area,
                                        int inside_cells, int max_depth_cells,
                                        const TraversabilityWeights& weights,
                                        Image<std::uint8_t>& furniture) {
  // Its fronts are the wall cells around a pocket's box, not pieces.
  const WallPieces walls = wall_pieces(grid, max_extent, max_area, 0);
  const Pieces pockets = pieces_of(pockets_between_walls(grid, 1, max_depth_cells, false));
  int fronts = 0;
  PocketSplit split;
  for (std::size_t p = 1; p < pockets.cells.size(); ++p) {
    std::set<int> beside;
    const std::vector<cv::Point>& pocket = pockets.cells[p];
    if (!backed_pocket(grid, walls, pocket, max_extent, max_area, beside)) continue;
    const JoinedFront joined = front_and_sides(grid, pocket);
    if (joined.cells.empty()) continue;
    ++fronts;
    split.add(grid, walls, pocket, inside_cells, std::span(&joined.back, 1));
    split.furniture.insert(split.furniture.end(), joined.cells.begin(), joined.cells.end());
  }
  split.mark(grid, weights, furniture);
  return {fronts, static_cast<int>(split.wall_inside.size())};
}

int pockets_behind_furniture(SemanticGrid& grid, double max_extent, double max_area,
                             int max_depth_cells, float weight, Image<std::uint8_t>& furniture) {
  const auto furniture_cell = [&](const Eigen::Vector2i& c) {
    return seen_as(grid, c, SemanticClass::furniture);
  };
  const auto end = [&](const Eigen::Vector2i& c) {
    return furniture_cell(c) || is_wall(grid, c.x(), c.y());
  };
  // A wall end with floor just behind it is the far face of a wall whose near face the furniture
  // hid: the run crossed the wall's inside, which is no pocket.
  const auto far_face = [&](const Eigen::Vector2i& c, const Eigen::Vector2i& out) {
    return !furniture_cell(c) && floor_within(grid, c, out, 2);
  };
  // A furniture end whose face the room saw: floor within 3 cells in front of it.
  const auto front = [&](const Eigen::Vector2i& c, const Eigen::Vector2i& out) {
    return furniture_cell(c) && floor_within(grid, c, out, 3);
  };
  const auto from_furniture = [&](const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
    const Eigen::Vector2i step = (b - a).cwiseSign();
    return (front(a, -step) || front(b, step)) && !far_face(a, -step) && !far_face(b, step);
  };
  cv::Mat hidden = cv::Mat::zeros(grid.height(), grid.width(), CV_8U);
  for (const Eigen::Vector2i& k :
       unobserved_runs_between(grid, end, 0, max_depth_cells, from_furniture))
    hidden.at<std::uint8_t>(k.y(), k.x()) = 255;
  const Pieces pockets = pieces_of(hidden);
  std::vector<cv::Point> to_furniture;
  int filled = 0;
  for (std::size_t p = 1; p < pockets.cells.size(); ++p) {
    const std::vector<cv::Point>& pocket = pockets.cells[p];
    if (!furniture_sized(pocket, grid.resolution, max_extent, max_area)) continue;
    if (beside_door(grid, pocket)) continue;
    ++filled;
    to_furniture.insert(to_furniture.end(), pocket.begin(), pocket.end());
  }
  mark_furniture(grid, to_furniture, weight, furniture);
  return filled;
}

namespace {

// How thick a layer of a face's points the depth noise spreads behind it, in cells (two cells of
// 5 cm: a few centimetres of noise at the surveys' 3-5 m ranges, and the cell it straddles).
constexpr int kNoiseLayerCells = 2;

// Whether wall closes every row of the piece at both ends (`step` (1, 0)), or every column
// (`step` (0, 1)): the piece lies inside a wall's line.
bool walled_in(const SemanticGrid& grid, const Pieces& pieces, int label,
               const Eigen::Vector2i& step) {
  for (const cv::Point& c : pieces.cells[static_cast<std::size_t>(label)]) {
    for (const int sign : {-1, 1}) {
      const Eigen::Vector2i n = Eigen::Vector2i(c.x, c.y) + sign * step;
      if (grid.contains(n) && pieces.labels.at<int>(n.y(), n.x()) == label) continue;
      if (!is_wall(grid, n.x(), n.y())) return false;
    }
  }
  return true;
}

// Whether the piece is a layer on a wall's face: no thicker than `reach` cells (what the depth
// noise spreads a face's points over), running along the face (at least twice as long as thick,
// or a cell or two), every cell within `reach` cells (8-neighbour steps) of a wall cell. A
// cabinet's corner behind a front the views took for wall is as near its walls, but as thick as
// long.
bool hugs_wall(const SemanticGrid& grid, const std::vector<cv::Point>& piece, int reach) {
  const cv::Rect box = cv::boundingRect(piece);
  const int thick = std::min(box.width, box.height), length = std::max(box.width, box.height);
  if (thick > reach || (length < 2 * thick && piece.size() > 2)) return false;
  for (const cv::Point& c : piece) {
    bool near = false;
    for (int dy = -reach; dy <= reach && !near; ++dy)
      for (int dx = -reach; dx <= reach && !near; ++dx) near = is_wall(grid, c.x + dx, c.y + dy);
    if (!near) return false;
  }
  return true;
}

// Whether seen floor lies among the 8 neighbours of any of the cells.
bool floor_around(const SemanticGrid& grid, const std::vector<cv::Point>& cells) {
  for (const cv::Point& c : cells)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (seen_as(grid, {c.x + dx, c.y + dy}, SemanticClass::floor)) return true;
  return false;
}

}  // namespace

int furniture_specks_in_walls(SemanticGrid& grid, int max_cells, float weight,
                              Image<std::uint8_t>& furniture) {
  const Pieces pieces = pieces_of(seen_mask(grid, SemanticClass::furniture));
  int specks = 0;
  for (std::size_t p = 1; p < pieces.cells.size(); ++p) {
    const std::vector<cv::Point>& piece = pieces.cells[p];
    if (floor_around(grid, piece)) continue;
    const int label = static_cast<int>(p);
    const bool small_in_line =
        piece.size() <= static_cast<std::size_t>(max_cells) &&
        (walled_in(grid, pieces, label, {1, 0}) || walled_in(grid, pieces, label, {0, 1}));
    if (!small_in_line && !hugs_wall(grid, piece, kNoiseLayerCells)) continue;
    ++specks;
    for (const cv::Point& c : piece) {
      grid.classes(c.x, c.y) = SemanticClass::wall;
      grid.weight(c.x, c.y) = weight;
      furniture(c.x, c.y) = 0;
    }
  }
  return specks;
}

Image<std::uint8_t> front_pockets(const SemanticGrid& grid, double max_extent, double max_area,
                                  int min_cells, int max_cells) {
  const WallPieces walls = wall_pieces(grid, max_extent, max_area, max_wall_across(min_cells));
  const auto front = [&](const Eigen::Vector2i& c) {
    return grid.contains(c) &&
           walls.front_like[static_cast<std::size_t>(walls.pieces.labels.at<int>(c.y(), c.x()))];
  };
  const auto wall_end = [&](const Eigen::Vector2i& c) { return is_wall(grid, c.x(), c.y()); };
  const auto front_at_either_end = [&](const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
    return front(a) || front(b);
  };
  Image<std::uint8_t> pockets(grid.width(), grid.height(), 0);
  for (const Eigen::Vector2i& k :
       unobserved_runs_between(grid, wall_end, min_cells, max_cells, front_at_either_end))
    pockets(k.x(), k.y()) = 1;
  return pockets;
}

}  // namespace kartograf::semantic::detail
