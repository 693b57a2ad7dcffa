#include "semantic/grid_walls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "semantic/grid_cells.hpp"

namespace kartograf::semantic::detail {
namespace {

constexpr int kBins = 8;

// Bin b's direction in cell coordinates (rows grow downwards, so the angle turns clockwise).
Eigen::Vector2d bin_direction(int bin) {
  const double angle = bin * std::numbers::pi / kBins;
  return {std::cos(angle), -std::sin(angle)};
}

// The cell `steps` unit steps from `from` along `direction`, rounded to the nearest cell.
Eigen::Vector2i cell_along(const Eigen::Vector2i& from, const Eigen::Vector2d& direction,
                           int steps) {
  const Eigen::Vector2d p = from.cast<double>() + steps * direction;
  return {static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y()))};
}

// Floor or furniture: what stands in front of a wall's face (or behind a wall seen from both
// sides).
bool free_or_furnished(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return seen_as(grid, c, SemanticClass::floor) || seen_as(grid, c, SemanticClass::furniture);
}

// A straight walk from a wall's face (a wall cell with floor or furniture just in front) back
// through the wall.
struct FaceRun {
  Eigen::Vector2i face;
  Eigen::Vector2d back;  // unit direction into the wall
  int wall_cells = 0;
};

// The runs back from every face, split by what lies behind the wall: floor (a wall seen from both
// sides, whose run measures its thickness) or unseen cells (a wall seen from one side).
struct FaceRuns {
  std::vector<int> two_sided_cells;
  std::vector<FaceRun> one_sided;
};

// With `through_unseen`, the walk goes on through cells no view saw (a wall's inside).
FaceRuns runs_from_faces(const SemanticGrid& grid, int max_cells, bool through_unseen = false) {
  const Image<int> bins = wall_direction_bins(grid.classes);
  FaceRuns runs;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      if (bins(col, row) < 0) continue;
      const Eigen::Vector2d along = bin_direction(bins(col, row));
      for (const double side : {-1.0, 1.0}) {
        FaceRun run{{col, row}, side * Eigen::Vector2d(-along.y(), along.x()), 0};
        if (!free_or_furnished(grid, cell_along(run.face, run.back, -1))) continue;
        const auto inside = [&](const Eigen::Vector2i& c) {
          return seen_as(grid, c, SemanticClass::wall) || (through_unseen && unobserved(grid, c));
        };
        while (run.wall_cells <= max_cells &&
               inside(cell_along(run.face, run.back, run.wall_cells)))
          ++run.wall_cells;
        if (run.wall_cells > max_cells) continue;  // along another wall, not through this one
        const Eigen::Vector2i behind = cell_along(run.face, run.back, run.wall_cells);
        if (free_or_furnished(grid, behind)) runs.two_sided_cells.push_back(run.wall_cells);
        if (unobserved(grid, behind)) runs.one_sided.push_back(run);
      }
    }
  }
  return runs;
}

}  // namespace

Image<int> wall_direction_bins(const Image<SemanticClass>& classes) {
  constexpr int kReach = 10;  // cells each way
  constexpr int kMinRun = 7;  // cells
  auto is_wall = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < classes.width() && y < classes.height() &&
           classes(x, y) == SemanticClass::wall;
  };
  Image<int> bins(classes.width(), classes.height(), -1);
  for (int row = 0; row < classes.height(); ++row) {
    for (int col = 0; col < classes.width(); ++col) {
      if (!is_wall(col, row)) continue;
      std::array<int, kBins> runs{};
      for (int b = 0; b < kBins; ++b) {
        int run = 1;
        for (const double sign : {-1.0, 1.0}) {
          int misses = 0;
          for (int t = 1; t <= kReach; ++t) {
            const Eigen::Vector2d p = Eigen::Vector2d(col, row) + sign * t * bin_direction(b);
            if (is_wall(static_cast<int>(std::lround(p.x())),
                        static_cast<int>(std::lround(p.y())))) {
              ++run, misses = 0;
            } else if (++misses > 1) {
              break;  // one missing cell is noise, two end the run
            }
          }
        }
        runs[b] = run;
      }
      const int best = static_cast<int>(std::max_element(runs.begin(), runs.end()) - runs.begin());
      if (runs[best] >= kMinRun && runs[best] >= 2 * runs[(best + kBins / 2) % kBins])
        bins(col, row) = best;
    }
  }
  return bins;
}

namespace {

constexpr double kPatchSize = 0.25;     // m: a stretch of face, short enough to be straight
constexpr double kMinPatchPoints = 20;  // fewer say nothing of a face
constexpr double kMaxFaceTilt = 20.0;   // deg between a patch's long axis and the lattice's
// Variance along a patch over variance across it (3x the spread): a face, not a corner.
constexpr double kMinElongation = 9.0;

// The wall points of one patch of the floor plan: their moments, and per axis the sum of their
// coordinates as angles on the cell period.
struct WallPatch {
  double count = 0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sum_sq = Eigen::Matrix2d::Zero();
  std::array<std::complex<double>, 2> resultant{};
};

using PatchMap = std::map<std::pair<long, long>, WallPatch>;

// The band's wall points, by patch, and the resultant of them all (summed in their order, as the
// lattice's offset has always been). Patches on two lattices half a patch apart: a face that one
// cuts, which leaves each part tighter than the face, lies inside a patch of the other.
struct WallBand {
  std::array<PatchMap, 2> patches;
  std::array<std::complex<double>, 2> resultant{};
};

WallBand wall_band(std::span<const Eigen::Vector3d> points, std::span<const SemanticClass> labels,
                   double floor_z, const SemanticGridParams& options) {
  const double to_angle = 2 * std::numbers::pi / options.resolution;
  WallBand band;
  // Consecutive points mostly come from neighbouring pixels, in one patch: the last one found
  // spares most of the lookups.
  std::array<std::pair<std::pair<long, long>, WallPatch*>, 2> last{};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const double h = p.z() - floor_z;
    if (labels[i] != SemanticClass::wall || !p.allFinite() || h < options.band_min ||
        h > options.band_max)
      continue;
    const Eigen::Vector2d xy = p.head<2>();
    std::array<WallPatch*, 2> sums_of{};
    for (std::size_t lattice = 0; lattice < 2; ++lattice) {
      const Eigen::Vector2d at = xy / kPatchSize + Eigen::Vector2d::Constant(0.5 * lattice);
      const std::pair<long, long> key{std::lround(std::floor(at.x())),
                                      std::lround(std::floor(at.y()))};
      if (!last[lattice].second || last[lattice].first != key)
        last[lattice] = {key, &band.patches[lattice][key]};
      sums_of[lattice] = last[lattice].second;
    }
    for (int axis = 0; axis < 2; ++axis) {
      const std::complex<double> angle = std::polar(1.0, to_angle * xy[axis]);
      band.resultant[axis] += angle;
      for (WallPatch* sums : sums_of) sums->resultant[axis] += angle;
    }
    for (WallPatch* sums : sums_of) {
      sums->count += 1;
      sums->sum += xy;
      sums->sum_sq += xy * xy.transpose();
    }
  }
  return band;
}

// Whether a patch's points lie along a face across `axis` (the wall runs along the other one).
bool face_across(const WallPatch& patch, int axis) {
  if (patch.count < kMinPatchPoints) return false;
  const Eigen::Vector2d mean = patch.sum / patch.count;
  const Eigen::Matrix2d covariance = patch.sum_sq / patch.count - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
  const Eigen::Vector2d spread = solver.eigenvalues();  // ascending
  return std::abs(solver.eigenvectors()(1 - axis, 1)) >=
             std::cos(kMaxFaceTilt * std::numbers::pi / 180) &&
         spread[1] >= kMinElongation * spread[0];
}

// How crisp the patches along faces across `axis` are: each one's points about its own offset.
double face_crispness(const PatchMap& patches, int axis) {
  double face_lengths = 0, face_points = 0;
  for (const auto& [key, patch] : patches) {
    if (!face_across(patch, axis)) continue;
    face_lengths += std::abs(patch.resultant[axis]);
    face_points += patch.count;
  }
  return face_points > 0 ? face_lengths / face_points : 0.0;
}

}  // namespace

FacePhase wall_face_phase(std::span<const Eigen::Vector3d> points,
                          std::span<const SemanticClass> labels, double floor_z,
                          const SemanticGridParams& options, double min_crispness) {
  const double res = options.resolution;
  const double to_angle = 2 * std::numbers::pi / res;
  const WallBand band = wall_band(points, labels, floor_z, options);
  FacePhase phase;
  for (int axis = 0; axis < 2; ++axis) {
    // A face that a patch boundary cuts reads tighter in each part than it is: the reading of
    // the lattice of patches that finds the faces less crisp.
    phase.crispness[axis] =
        std::min(face_crispness(band.patches[0], axis), face_crispness(band.patches[1], axis));
    if (phase.crispness[axis] < min_crispness) continue;
    const double offset = std::arg(band.resultant[axis]) / to_angle;  // (-res / 2, res / 2]
    phase.offset[axis] = offset < 0 ? offset + res : offset;
  }
  return phase;
}

int two_sided_wall_thickness(const SemanticGrid& grid, int max_cells, int min_samples,
                             bool through_unseen) {
  // A run of one cell is a stray row of wall cells with floor on both sides (a face's spill, a
  // duplicated face), not a wall's cross-section: 30-50 % of the runs on the synthetic surveys.
  std::vector<int> histogram(static_cast<std::size_t>(std::max(max_cells, 0)) + 2, 0);
  int samples = 0;
  for (int cells : runs_from_faces(grid, max_cells, through_unseen).two_sided_cells) {
    if (cells < 2) continue;
    ++histogram[static_cast<std::size_t>(std::min(cells, max_cells + 1))];
    ++samples;
  }
  if (samples < std::max(min_samples, 1)) return 0;
  // A wall k cells thick covers k or k + 1 cells by where its faces fall, so it is the k whose
  // two bins hold the most runs. Drift moves faces both ways: a lower quantile took 2 cells for a
  // 0.15 m wall (3) on a survey whose two visits of its walls met a few centimetres apart.
  int best = 0, best_count = -1;
  for (int k = 2; k <= max_cells; ++k) {
    const int count =
        histogram[static_cast<std::size_t>(k)] + histogram[static_cast<std::size_t>(k + 1)];
    if (count > best_count) best = k, best_count = count;
  }
  return best;
}

void back_one_sided_walls(SemanticGrid& grid, int thickness, int max_cells, float weight) {
  if (thickness <= 0) return;
  const FaceRuns runs = runs_from_faces(grid, max_cells);
  std::vector<Eigen::Vector2i> backing;
  for (const FaceRun& run : runs.one_sided) {
    for (int t = run.wall_cells; t < thickness; ++t) {
      const Eigen::Vector2i c = cell_along(run.face, run.back, t);
      if (!unobserved(grid, c)) break;  // something seen there: it is no wall's hidden back
      backing.push_back(c);
    }
  }
  set_class(grid, backing, SemanticClass::wall, weight);
}

namespace {

// Whether wall runs on for `enough` cells from the cell one way or the other along `step`'s axis.
bool wall_either_way(const SemanticGrid& grid, const Eigen::Vector2i& cell,
                     const Eigen::Vector2i& step, int enough) {
  return wall_run(grid, cell, step, enough) >= enough ||
         wall_run(grid, cell, -step, enough) >= enough;
}

// Unseen, or seen as furniture: where a wall line may run on behind furniture.
bool hidden_by_furniture(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return unobserved(grid, c) || seen_as(grid, c, SemanticClass::furniture);
}

// Whether a furniture cell lies within `reach` cells of c along `across`, either way.
bool furniture_across(const SemanticGrid& grid, const Eigen::Vector2i& c,
                      const Eigen::Vector2i& across, int reach) {
  for (int k = -reach; k <= reach; ++k)
    if (seen_as(grid, c + k * across, SemanticClass::furniture)) return true;
  return false;
}

}  // namespace

void fill_wall_corners(SemanticGrid& grid, int thickness, float weight) {
  constexpr int kArm = 3;  // cells of wall along each arm of the corner
  // A block k cells square fills from its inner corner along anti-diagonals: 2k - 1 rounds.
  for (int round = 0; round < 2 * thickness - 1; ++round) {
    std::vector<Eigen::Vector2i> corners;
    for (int row = 0; row < grid.height(); ++row) {
      for (int col = 0; col < grid.width(); ++col) {
        const Eigen::Vector2i c(col, row);
        if (unobserved(grid, c) && wall_either_way(grid, c, {1, 0}, kArm) &&
            wall_either_way(grid, c, {0, 1}, kArm))
          corners.push_back(c);
      }
    }
    if (corners.empty()) return;
    set_class(grid, corners, SemanticClass::wall, weight);
  }
}

namespace {

// Whether a line along `step` from wall cell `start` to wall cell `end` is a wall between two rooms
// that meets another wall (a T), where cabinets standing against both hid where they meet: within
// `beyond` cells behind `start` the rooms on both its sides saw it (at most `beyond` - 1 cells
// thick), and the wall reached at `end` runs across the line for `beyond` cells both ways in one
// of its first `beyond` rows. The top edge of a thicker piece of wall (a cabinet the views took for
// one) is no wall between rooms.
bool meets_wall_across(const SemanticGrid& grid, const Eigen::Vector2i& start,
                       const Eigen::Vector2i& end, const Eigen::Vector2i& step, int beyond) {
  const Eigen::Vector2i across(step.y(), step.x());
  bool between_rooms = false;
  for (int k = 0; k < beyond && !between_rooms; ++k)
    between_rooms = floor_beyond_both_faces(grid, start - k * step, across, beyond - 1);
  if (!between_rooms) return false;
  for (Eigen::Vector2i k = end;
       (k - end).cwiseAbs().sum() < beyond && seen_as(grid, k, SemanticClass::wall); k += step) {
    if (wall_run(grid, k, across, beyond) >= beyond && wall_run(grid, k, -across, beyond) >= beyond)
      return true;
  }
  return false;
}

}  // namespace

int wall_lines_behind_furniture(SemanticGrid& grid, int max_gap_cells, int beyond_cells,
                                float weight, Image<std::uint8_t>& furniture) {
  const auto hidden = [&](const Eigen::Vector2i& c) { return hidden_by_furniture(grid, c); };
  std::vector<Eigen::Vector2i> bridged;
  // Each way: a line that meets a wall (a T) is found from its open end only.
  for (const Eigen::Vector2i& step : kFourNeighbours) {
    const Eigen::Vector2i across(step.y(), step.x());
    for (int row = 0; row < grid.height(); ++row) {
      for (int col = 0; col < grid.width(); ++col) {
        const Eigen::Vector2i start(col, row);
        if (!seen_as(grid, start, SemanticClass::wall) || !hidden(start + step) ||
            wall_run(grid, start, -step, beyond_cells) < beyond_cells)
          continue;
        Eigen::Vector2i c = start + step;
        int gap = 0;
        bool furniture = false;
        for (; hidden(c) && gap <= max_gap_cells; c += step, ++gap)
          furniture |= furniture_across(grid, c, across, beyond_cells);
        if (gap > max_gap_cells || !furniture || !seen_as(grid, c, SemanticClass::wall) ||
            (wall_run(grid, c, step, beyond_cells) < beyond_cells &&
             !meets_wall_across(grid, start, c, step, beyond_cells)))
          continue;
        for (Eigen::Vector2i k = start + step; k != c; k += step) bridged.push_back(k);
      }
    }
  }
  int from_furniture = 0;
  for (const Eigen::Vector2i& c : bridged) {
    if (seen_as(grid, c, SemanticClass::wall)) continue;  // bridged along both axes
    from_furniture += seen_as(grid, c, SemanticClass::furniture) ? 1 : 0;
    grid.classes(c.x(), c.y()) = SemanticClass::wall;
    grid.weight(c.x(), c.y()) = weight;
    furniture(c.x(), c.y()) = 0;
  }
  return from_furniture;
}

namespace {

// Unseen, or an obstacle the views could not name: where a wall line may run on unseen.
bool unseen_or_unnamed(const SemanticGrid& grid, const Eigen::Vector2i& c) {
  return unobserved(grid, c) || unclassified_obstacle(grid, c);
}

// The gap's cells from `start` (a wall cell, not included) along `step` up to a wall cell, when
// all are unseen or unnamed, at most `max_gap` of them, and at most half of them run beside a
// wall (a line along a wall's side is its thickness or its outside, not a wall of its own).
std::vector<Eigen::Vector2i> unseen_gap_to_wall(const SemanticGrid& grid,
                                                const Eigen::Vector2i& start,
                                                const Eigen::Vector2i& step, int max_gap) {
  const Eigen::Vector2i across(step.y(), step.x());
  std::vector<Eigen::Vector2i> gap;
  int beside_wall = 0;
  Eigen::Vector2i c = start + step;
  for (; unseen_or_unnamed(grid, c); c += step) {
    if (static_cast<int>(gap.size()) == max_gap) return {};
    gap.push_back(c);
    beside_wall += seen_as(grid, c + across, SemanticClass::wall) ||
                   seen_as(grid, c - across, SemanticClass::wall);
  }
  if (!seen_as(grid, c, SemanticClass::wall) || 2 * beside_wall > static_cast<int>(gap.size()))
    return {};
  return gap;
}

}  // namespace

int wall_lines_across_unseen(SemanticGrid& grid, int max_gap_cells, int beyond_cells,
                             float weight) {
  std::vector<Eigen::Vector2i> bridged;
  for (const Eigen::Vector2i& step : kFourNeighbours) {
    for (int row = 0; row < grid.height(); ++row) {
      for (int col = 0; col < grid.width(); ++col) {
        const Eigen::Vector2i start(col, row);
        if (!seen_as(grid, start, SemanticClass::wall) || !unseen_or_unnamed(grid, start + step) ||
            wall_run(grid, start, -step, beyond_cells) < beyond_cells)
          continue;
        const std::vector<Eigen::Vector2i> gap =
            unseen_gap_to_wall(grid, start, step, max_gap_cells);
        bridged.insert(bridged.end(), gap.begin(), gap.end());
      }
    }
  }
  int made_wall = 0;
  for (const Eigen::Vector2i& c : bridged) {
    if (seen_as(grid, c, SemanticClass::wall)) continue;  // bridged from both ends
    grid.classes(c.x(), c.y()) = SemanticClass::wall;
    grid.weight(c.x(), c.y()) = weight;
    ++made_wall;
  }
  return made_wall;
}

namespace {

// The cells of an L from `start` (a wall cell, not included) through hidden cells along `step`,
// then along `turn`, to a wall cell that runs on beyond it, with furniture within `beyond` across
// a leg; empty when there is none within `max_gap` cells on either leg.
std::vector<Eigen::Vector2i> hidden_corner(const SemanticGrid& grid, const Eigen::Vector2i& start,
                                           const Eigen::Vector2i& step, int max_gap, int beyond) {
  const auto hidden = [&](const Eigen::Vector2i& c) { return hidden_by_furniture(grid, c); };
  const Eigen::Vector2i side(step.y(), step.x());
  bool furniture = false;
  Eigen::Vector2i c = start + step;
  for (int gap = 1; gap <= max_gap && hidden(c); ++gap, c += step) {
    furniture |= furniture_across(grid, c, side, beyond);
    for (const Eigen::Vector2i& turn : {side, Eigen::Vector2i(-side)}) {
      bool near_furniture = furniture;
      Eigen::Vector2i e = c + turn;
      int length = 1;
      for (; length <= max_gap && hidden(e); ++length, e += turn)
        near_furniture |= furniture_across(grid, e, step, beyond);
      if (length > max_gap || !near_furniture || !seen_as(grid, e, SemanticClass::wall) ||
          wall_run(grid, e, turn, beyond) < beyond)
        continue;
      std::vector<Eigen::Vector2i> cells;
      for (Eigen::Vector2i k = start + step; k != c + step; k += step) cells.push_back(k);
      for (Eigen::Vector2i k = c + turn; k != e; k += turn) cells.push_back(k);
      return cells;
    }
  }
  return {};
}

}  // namespace

int wall_corners_behind_furniture(SemanticGrid& grid, int max_gap_cells, int beyond_cells,
                                  float weight) {
  std::vector<Eigen::Vector2i> bridged;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const Eigen::Vector2i start(col, row);
      if (!seen_as(grid, start, SemanticClass::wall)) continue;
      for (const Eigen::Vector2i& step : kFourNeighbours) {
        if (wall_run(grid, start, -step, beyond_cells) < beyond_cells) continue;
        const std::vector<Eigen::Vector2i> corner =
            hidden_corner(grid, start, step, max_gap_cells, beyond_cells);
        bridged.insert(bridged.end(), corner.begin(), corner.end());
      }
    }
  }
  int made = 0;
  for (const Eigen::Vector2i& c : bridged) {
    if (seen_as(grid, c, SemanticClass::wall)) continue;  // on two corners' legs
    grid.classes(c.x(), c.y()) = SemanticClass::wall;
    grid.weight(c.x(), c.y()) = weight;
    ++made;
  }
  return made;
}

}  // namespace kartograf::semantic::detail
