#include "cell_planes.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>

#include "cell_scores_wide.hpp"
#include "compute/cpu/lanes.hpp"
#include "compute/cpu/wide_lanes.hpp"
#include "compute/cpu_parallel.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/segmentation/lab_color.hpp"
#include "kartograf/segmentation/plane_fit.hpp"
#include "kernels/cell_blocks/cell_blocks.h"
#include "kernels/cell_scores/cell_scores.h"
#include "plane_output.hpp"

namespace kartograf::segmentation::detail {

namespace {

using compute::detail::LaneMask;
using compute::detail::Lanes;
using compute::detail::select;
using compute::detail::splat;

constexpr compute::KernelSpec kCellBlocksKernel{"cell_blocks", KG_CELL_BLOCKS_LOCAL_X};
constexpr compute::KernelSpec kCellScoresKernel{"cell_scores", KG_CELL_SCORES_LOCAL_X};

// A block's moments about `origin` in double, from its float sums about its reference point (the
// shift of sums of outer products is exact algebra).
geometry::SegmentMoments block_moments(const float* sums, std::uint32_t count,
                                       const Eigen::Vector3d& origin) {
  geometry::SegmentMoments m;
  m.count = count;
  if (count == 0) return m;
  const Eigen::Vector3d reference(sums[0], sums[1], sums[2]);
  const Eigen::Vector3d s(sums[3], sums[4], sums[5]);
  const double xx = sums[6], xy = sums[7], xz = sums[8], yy = sums[9], yz = sums[10], zz = sums[11];
  const Eigen::Vector3d shift = reference - origin;
  Eigen::Matrix3d outer;
  outer << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  const double n = count;
  m.sum = s + n * shift;
  m.sum_outer =
      outer + s * shift.transpose() + shift * s.transpose() + n * shift * shift.transpose();
  return m;
}

// The colour image as the kernel reads it: bytes on the CPU (the image itself), 32-bit words on
// a device (a copy padded to whole words).
void colours_to_backend(const compute::Context& context, const RgbImage& rgb,
                        compute::RawBuffer& colours) {
  const std::size_t bytes = rgb.size() * sizeof(Rgb8);
  if (context.is_cpu() || bytes % 4 == 0) {
    colours.refer_or_upload(context, rgb.data(), bytes);
    return;
  }
  std::vector<std::uint8_t> padded(bytes + 4 - bytes % 4, 0);
  std::memcpy(padded.data(), rgb.data(), bytes);
  colours.refer_or_upload(context, padded.data(), padded.size());
}

// Cells from the kernel's block records: each block's moments, colour and continuity, and each
// cell's sums over its blocks.
void cells_from_blocks(const compute::HostView<float>& sums,
                       const compute::HostView<std::uint32_t>& counts,
                       const Eigen::Vector3d& origin, CellGrid& cells) {
  const int half = cells.cell_size / 2;
  compute::detail::for_each_chunk(
      cells.size(), cells.size() * 4, [&](std::size_t begin, std::size_t end, std::size_t) {
        for (std::size_t c = begin; c < end; ++c) {
          const std::size_t bx = 2 * (c % cells.columns), by = 2 * (c / cells.columns);
          std::uint32_t cell_jumps = 0;
          for (std::size_t b = 0; b < 4; ++b) {
            const std::size_t block = (by + b / 2) * cells.blocks_x + bx + b % 2;
            const std::uint32_t* n = counts.data() + block * KG_CELL_BLOCK_COUNTS;
            const std::size_t k = 4 * c + b;
            cells.block_moments[k] = block_moments(sums.data() + block * KG_CELL_BLOCK_SUMS,
                                                   n[KG_CELL_BLOCK_COUNT], origin);
            cells.block_colours[k] = Eigen::Vector3d(n[1], n[2], n[3]);
            // An edge across a block jumps on every row or column it crosses; depth noise and
            // quantization far away jump here and there.
            const std::uint32_t inside = n[KG_CELL_BLOCK_INSIDE_JUMPS];
            cells.block_continuous[k] = 2 * inside <= static_cast<std::uint32_t>(half);
            cell_jumps += inside + n[KG_CELL_BLOCK_EDGE_JUMPS];
            cells.moments[c] += cells.block_moments[k];
          }
          cells.continuous[c] = 2 * cell_jumps <= static_cast<std::uint32_t>(cells.cell_size);
        }
      });
}

}  // namespace

void measure_cells(const compute::Context& context, const compute::Buffer<Point4f>& points,
                   const RgbImage& rgb, int cell_size, float max_depth_jump, float jump_per_z2,
                   const Eigen::Vector3d& origin, CellBuffers& buffers, CellGrid& cells) {
  const int half = cell_size / 2;
  cells.cell_size = cell_size;
  cells.width = rgb.width(), cells.height = rgb.height();
  cells.columns = (rgb.width() + cell_size - 1) / cell_size;
  cells.rows = (rgb.height() + cell_size - 1) / cell_size;
  cells.blocks_x = 2 * cells.columns;
  cells.mask_words = (half * half + 31) / 32;
  const std::size_t count = static_cast<std::size_t>(cells.columns) * cells.rows;
  const kernels::CellBlocksParams params{static_cast<std::uint32_t>(rgb.width()),
                                         static_cast<std::uint32_t>(rgb.height()),
                                         static_cast<std::uint32_t>(half),
                                         static_cast<std::uint32_t>(cells.blocks_x),
                                         static_cast<std::uint32_t>(4 * count),
                                         static_cast<std::uint32_t>(cells.mask_words),
                                         max_depth_jump,
                                         jump_per_z2};
  if (buffers.counts.size() != 4 * count * KG_CELL_BLOCK_COUNTS ||
      buffers.masks.size() != 4 * count * cells.mask_words) {
    buffers.sums = compute::Buffer<float>(context, 4 * count * KG_CELL_BLOCK_SUMS);
    buffers.counts = compute::Buffer<std::uint32_t>(context, 4 * count * KG_CELL_BLOCK_COUNTS);
    buffers.masks = compute::Buffer<std::uint32_t>(context, 4 * count * cells.mask_words);
  }
  colours_to_backend(context, rgb, buffers.colours);
  compute::dispatch(context, kCellBlocksKernel,
                    {points, buffers.colours, buffers.sums, buffers.counts, buffers.masks}, params,
                    {compute::groups_for(4 * count, kCellBlocksKernel.local_x)});
  cells.moments.assign(count, {});
  cells.continuous.assign(count, 0);
  cells.block_moments.assign(4 * count, {});
  cells.block_continuous.assign(4 * count, 0);
  cells.block_colours.assign(4 * count, Eigen::Vector3d::Zero());
  cells_from_blocks(compute::HostView<float>(buffers.sums),
                    compute::HostView<std::uint32_t>(buffers.counts), origin, cells);
  const compute::HostView<std::uint32_t> masks(buffers.masks);
  cells.block_masks.assign(masks.begin(), masks.end());
  // After the loop: an Error thrown on a helper thread would end the process.
  for (const geometry::SegmentMoments& m : cells.moments) {
    require(m.sum.allFinite() && m.sum_outer.allFinite(),
            "plane extraction: a point has an infinite coordinate");
  }
}

namespace {

// The piece's fit when it is planar, else none. min_facing: the cosine of the merge's incidence
// limit.
std::optional<SegmentPlane> planar_piece(const CellPlaneParams& params,
                                         const PlaneMergeParams& merge,
                                         const geometry::SegmentMoments& moments,
                                         const Eigen::Vector3d& origin, std::uint64_t min_count,
                                         double min_facing) {
  if (moments.count < std::max<std::uint64_t>(min_count, 3)) return std::nullopt;
  SegmentPlane fit = fit_plane(moments, origin, merge.fit);
  if (!fit.valid) return std::nullopt;
  const double z = fit.centroid.z();
  if (fit.rms_error > params.rms_base + params.rms_per_z2 * z * z) return std::nullopt;
  // A surface seen edge-on is no plane to this sensor (the merge's incidence limit).
  const double facing = std::fabs(fit.normal.dot(fit.centroid.normalized()));
  if (facing < min_facing) return std::nullopt;
  return fit;
}

// Sum of x, sum of y and count of the pixels of the rectangle [x0, x1) x [y0, y1).
Eigen::Vector3d rectangle_pixel_sums(int x0, int y0, int x1, int y1) {
  const double w = x1 - x0, h = y1 - y0;
  return {h * (x0 + x1 - 1) * w / 2, w * (y0 + y1 - 1) * h / 2, w * h};
}

Eigen::Vector3f mean_lab(const Eigen::Vector3d& colour_sum, std::uint64_t count) {
  const Eigen::Vector3d mean = colour_sum / static_cast<double>(count);
  const Rgb8 rgb{static_cast<std::uint8_t>(std::lround(mean.x())),
                 static_cast<std::uint8_t>(std::lround(mean.y())),
                 static_cast<std::uint8_t>(std::lround(mean.z()))};
  return rgb_to_lab(rgb);
}

// The pixel sums of the square of `size` pixels at (x0, y0), cut by the image.
Eigen::Vector3d square_pixel_sums(int width, int height, int x0, int y0, int size) {
  return rectangle_pixel_sums(x0, y0, std::min(width, x0 + size), std::min(height, y0 + size));
}

// A planar cell (block -1) or block of a cell, with its fit and mean colour.
struct PlanarPiece {
  std::size_t cell;
  int block;
  SegmentPlane fit;
  Eigen::Vector3f lab;
};

// The planar pieces of cells [begin, end), in order: the cell when it is planar as a whole, else
// its planar blocks.
void planar_pieces(const CellPlaneParams& params, const PlaneMergeParams& merge,
                   const Eigen::Vector3d& origin, const CellGrid& cells, std::size_t begin,
                   std::size_t end, std::vector<PlanarPiece>& out) {
  const int size = cells.cell_size, half = size / 2;
  const auto min_count = [&](int side) {
    return static_cast<std::uint64_t>(std::ceil(params.min_valid_fraction * side * side));
  };
  const double min_facing = std::cos(merge.max_incidence_deg * M_PI / 180.0);
  for (std::size_t c = begin; c < end; ++c) {
    const std::optional<SegmentPlane> cell_fit =
        cells.continuous[c]
            ? planar_piece(params, merge, cells.moments[c], origin, min_count(size), min_facing)
            : std::nullopt;
    if (cell_fit) {
      const std::size_t k = 4 * c;
      const Eigen::Vector3d colour = cells.block_colours[k] + cells.block_colours[k + 1] +
                                     cells.block_colours[k + 2] + cells.block_colours[k + 3];
      out.push_back({c, -1, *cell_fit, mean_lab(colour, cells.moments[c].count)});
      continue;
    }
    for (int b = 0; b < 4; ++b) {
      const std::size_t k = 4 * c + static_cast<std::size_t>(b);
      if (!cells.block_continuous[k]) continue;
      const std::optional<SegmentPlane> fit =
          planar_piece(params, merge, cells.block_moments[k], origin, min_count(half), min_facing);
      if (fit)
        out.push_back({c, b, *fit, mean_lab(cells.block_colours[k], cells.block_moments[k].count)});
    }
  }
}

}  // namespace

std::uint32_t planar_cell_segments(const CellPlaneParams& params, const PlaneMergeParams& merge,
                                   const Eigen::Vector3d& origin, CellGrid& cells,
                                   CellSegments& segments) {
  constexpr std::uint32_t kNone = geometry::kNoLabel;
  cells.segments.assign(cells.size(), {kNone, kNone, kNone, kNone});
  segments = {};
  segments.moments.origin = origin;
  // The fits over the threads; the segments numbered in cell order after (chunks in order).
  std::array<std::vector<PlanarPiece>, compute::detail::kCpuChunks> pieces;
  compute::detail::for_each_chunk(
      cells.size(), cells.size() * static_cast<std::size_t>(cells.cell_size * cells.cell_size),
      [&](std::size_t begin, std::size_t end, std::size_t chunk) {
        planar_pieces(params, merge, origin, cells, begin, end, pieces[chunk]);
      });
  const int half = cells.cell_size / 2;
  for (const std::vector<PlanarPiece>& chunk : pieces) {
    for (const PlanarPiece& piece : chunk) {
      const auto segment = static_cast<std::uint32_t>(segments.fits.size());
      const bool whole = piece.block < 0;
      const std::size_t k = 4 * piece.cell + static_cast<std::size_t>(std::max(piece.block, 0));
      const int x0 = cells.first_x(piece.cell) + (whole ? 0 : piece.block % 2 * half);
      const int y0 = cells.first_y(piece.cell) + (whole ? 0 : piece.block / 2 * half);
      segments.moments.segments.push_back(whole ? cells.moments[piece.cell]
                                                : cells.block_moments[k]);
      segments.fits.push_back(piece.fit);
      segments.lab_colours.push_back(piece.lab);
      segments.pixel_sums.push_back(
          square_pixel_sums(cells.width, cells.height, x0, y0, whole ? cells.cell_size : half));
      if (whole) {
        cells.segments[piece.cell].fill(segment);
      } else {
        cells.segments[piece.cell][static_cast<std::size_t>(piece.block)] = segment;
      }
    }
  }
  return static_cast<std::uint32_t>(segments.fits.size());
}

SegmentGraph cell_segment_graph(const CellGrid& cells, std::uint32_t segment_count) {
  const int columns = 2 * cells.columns, rows = 2 * cells.rows;  // blocks
  std::vector<std::uint64_t> edges;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < columns; ++x) {
      const std::uint32_t a = cells.block_segment(x, y);
      if (a == geometry::kNoLabel) continue;
      // Right, down-left, down, down-right: each neighbouring pair once.
      const int steps[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
      for (const auto& step : steps) {
        const int nx = x + step[0], ny = y + step[1];
        if (nx < 0 || nx >= columns || ny >= rows) continue;
        const std::uint32_t b = cells.block_segment(nx, ny);
        if (b == geometry::kNoLabel || b == a) continue;
        // A cell's blocks share its segment: the same pair comes up block after block.
        const std::uint64_t edge = segment_edge(a, b);
        if (edges.empty() || edges.back() != edge) edges.push_back(edge);
      }
    }
  }
  return graph_from_edges(edges, segment_count);
}

namespace {

// The distinct planes of a cell and its 8 neighbours (kNoLabel left out), the cell's own first;
// `own`: the cell lies in one plane; `whole`: so do all its neighbours inside the image, in the
// same one.
struct CellCandidates {
  std::array<std::uint32_t, 36> planes;
  int count = 0;
  bool own = false, whole = false;

  void add(std::uint32_t plane) {
    if (plane != geometry::kNoLabel &&
        std::find(planes.begin(), planes.begin() + count, plane) == planes.begin() + count)
      planes[count++] = plane;
  }
};

// PlanesOf(cell): the cell's planes (a std::array of 4, kNoLabel where none); a cell is whole in
// a plane when all four are it.
template <class PlanesOf>
CellCandidates candidates_of(const CellGrid& cells, std::size_t cell, PlanesOf&& planes_of) {
  CellCandidates out;
  const auto in_one = [](const std::array<std::uint32_t, 4>& p) {
    return p[0] != geometry::kNoLabel && p[0] == p[1] && p[0] == p[2] && p[0] == p[3];
  };
  // A cell's entries repeat (a cell in one plane has it four times): a repeat of the entry
  // before it adds nothing, and is skipped without searching the list.
  const auto add_all = [&out](const std::array<std::uint32_t, 4>& p) {
    out.add(p[0]);
    for (std::size_t k = 1; k < 4; ++k) {
      if (p[k] != p[k - 1]) out.add(p[k]);
    }
  };
  const std::array<std::uint32_t, 4> own = planes_of(cell);
  add_all(own);
  out.own = out.whole = in_one(own);
  const int cx = static_cast<int>(cell % cells.columns),
            cy = static_cast<int>(cell / cells.columns);
  for (int y = std::max(0, cy - 1); y <= std::min(cells.rows - 1, cy + 1); ++y) {
    for (int x = std::max(0, cx - 1); x <= std::min(cells.columns - 1, cx + 1); ++x) {
      const std::array<std::uint32_t, 4> p =
          planes_of(static_cast<std::size_t>(y) * cells.columns + x);
      out.whole = out.whole && in_one(p) && p[0] == own[0];
      add_all(p);
    }
  }
  return out;
}

// A plane as the per-pixel score reads it, in float (plane_score's rule).
struct ScoredPlane {
  Eigen::Vector3f normal;
  float offset;
};

// Four pixels of a row (a lane without a point holds NaN, which compares false: it takes none).
struct PixelLanes {
  Lanes x, y, z;
};

// A cell's candidate planes, each coefficient in all four lanes.
struct CandidateLanes {
  std::array<Lanes, 36> nx, ny, nz, offset;
  int count = 0;
};

// plane_score's rule without divisions or roots, four pixels at once: a pixel's score against a
// plane is distance / (base facing) with distance = |n . p + offset|, facing = max(|n . p| /
// |p|, min) and base = distance_base + distance_per_z2 z^2; so score^2 = distance^2 |p|^2 /
// (base^2 max((n . p)^2, min^2 |p|^2)), whose parts (none negative) are compared by
// cross-multiplying. The device's rule (kernels/cell_scores, cell_choice) does the same float
// operations in the same order, so both choose alike (the cells mode's labels on every backend
// equal the CPU's: PlaneExtractionBackendTest.CellsModeAgreesWithTheCpuBackend).
struct ScoreRule {
  float distance_base, distance_per_z2, min_facing;

  // Per lane: the index of the candidate with the lowest score below 1, or -1; `distance2`: the
  // point's squared distance to that candidate.
  LaneMask best(const CandidateLanes& planes, const PixelLanes& p, Lanes& distance2) const {
    const Lanes range2 = p.x * p.x + p.y * p.y + p.z * p.z;
    const Lanes floor2 = splat(min_facing * min_facing) * range2;
    Lanes best_d2 = splat(1.0f), best_s2 = splat(0.0f);  // no candidate yet: 1 / 0
    LaneMask choice = splat(-1);
    for (int k = 0; k < planes.count; ++k) {
      const Lanes along = planes.nx[k] * p.x + planes.ny[k] * p.y + planes.nz[k] * p.z;
      const Lanes d = along + planes.offset[k];
      const Lanes d2 = d * d, a2 = along * along;
      const Lanes s2 = select(a2 > floor2, a2, floor2);
      const LaneMask better = d2 * best_s2 < best_d2 * s2;
      best_d2 = select(better, d2, best_d2);
      best_s2 = select(better, s2, best_s2);
      choice = select(better, splat(k), choice);
    }
    const Lanes base = splat(distance_base) + splat(distance_per_z2) * p.z * p.z;
    distance2 = best_d2;
    return select(best_d2 * range2 < base * base * best_s2, choice, splat(-1));
  }
};

// The scoring jobs of a pass (a cell's or block's rectangle with its candidates, in the order the
// assignment meets them) and, off the CPU backend, the device's choices for their pixels
// (kernels/cell_scores), each job's pixels row by row from its slot.
struct ScoringJobs {
  std::vector<std::uint32_t> words;       // KG_CELL_JOB_WORDS per job
  std::vector<std::uint32_t> candidates;  // the jobs' candidate planes, one after the other
  std::size_t pixels = 0;
  std::vector<std::uint32_t> choices;  // per job pixel: candidate index or KG_CELL_NO_CHOICE
  std::vector<float> distances;        // per job pixel: squared distance to it

  std::size_t slot(std::size_t job) const { return words[job * KG_CELL_JOB_WORDS + 6]; }
};

// What every cell's assignment reads.
struct AssignInputs {
  const PointImage& points;
  const CellGrid& cells;
  const std::vector<SegmentPlane>& planes;
  Eigen::Vector3d origin;  // of the cells' moments
  std::vector<ScoredPlane> scored;
  std::vector<PlaneFrame> frames;
  ScoreRule rule;
  const std::vector<std::array<std::uint32_t, 4>>* block_planes = nullptr;  // per cell's blocks
  const ScoringJobs* device = nullptr;  // the device's choices, off the CPU backend
};

// A rectangle of pixels: a cell, or one of its blocks; x0 and x1 on block columns.
struct PixelRect {
  int x0, y0, x1, y1;
};

PixelRect cell_rect(const AssignInputs& in, std::size_t cell) {
  const int x0 = in.cells.first_x(cell), y0 = in.cells.first_y(cell);
  return {x0, y0, std::min(in.points.width(), x0 + in.cells.cell_size),
          std::min(in.points.height(), y0 + in.cells.cell_size)};
}

// Block b (0..3, row by row) of a cell.
PixelRect block_rect(const AssignInputs& in, std::size_t cell, int b) {
  const int half = in.cells.cell_size / 2;
  const int x0 = in.cells.first_x(cell) + (b % 2) * half,
            y0 = in.cells.first_y(cell) + (b / 2) * half;
  return {x0, y0, std::min(in.points.width(), x0 + half), std::min(in.points.height(), y0 + half)};
}

// f(y, bits) for each row y of the rectangle, bit k of `bits`: whether pixel (rect.x0 + k, y) has
// a point (bits past the image's edge are never set).
template <class RowBits>
void for_each_row_bits(const CellGrid& cells, const PixelRect& rect, RowBits&& f) {
  const int half = cells.cell_size / 2;
  const std::size_t block_x = static_cast<std::size_t>(rect.x0 / half);
  const bool two = rect.x1 - rect.x0 > half;  // a cell's two blocks across, or one
  for (int y0 = rect.y0; y0 < rect.y1; y0 += half) {
    const std::size_t block = static_cast<std::size_t>(y0 / half) * cells.blocks_x + block_x;
    for (int row = 0; row < half && y0 + row < rect.y1; ++row) {
      std::uint64_t bits = cells.block_row_bits(block, row);
      if (two) bits |= std::uint64_t{cells.block_row_bits(block + 1, row)} << half;
      f(y0 + row, bits);
    }
  }
}

// out[k] = plane for every set bit k, run by run.
void label_bits(std::uint32_t* out, std::uint64_t bits, std::uint32_t plane) {
  while (bits != 0) {
    const int start = std::countr_zero(bits);
    const int run = std::countr_one(bits >> start);
    std::fill_n(out + start, run, plane);
    bits = run + start >= 64 ? 0 : bits & (~std::uint64_t{0} << (start + run));
  }
}

// A planar cell (or block) whose neighbours hold no other plane: its valid pixels take its plane
// (its planarity test and the merge have judged them), and its moments give the plane's count
// and squared distances. A plane's image and its in-plane coordinates are related by a
// homography, which keeps convex hulls: a plane's extreme points lie on its outline in the image,
// never inside. So the rectangle adds to the extent only the first and last valid pixel of each
// row (the corners of its pixels' hull are among them), and one whose neighbours all lie in the
// plane (`inside`, away from the image's edge) adds nothing.
void assign_whole(const AssignInputs& in, const PixelRect& rect, const geometry::SegmentMoments& m,
                  std::uint32_t plane, bool inside, std::vector<PlanePixelSums>& sums,
                  std::vector<std::uint32_t>& pixel_plane) {
  const int width = in.points.width();
  const PlaneFrame& frame = in.frames[plane];
  PlanePixelSums& sum = sums[plane];
  for_each_row_bits(in.cells, rect, [&](int y, std::uint64_t bits) {
    if (bits == 0) return;
    const std::size_t row = static_cast<std::size_t>(y) * width;
    label_bits(pixel_plane.data() + row + rect.x0, bits, plane);
    if (inside) return;
    const int first = rect.x0 + std::countr_zero(bits),
              last = rect.x0 + 63 - std::countl_zero(bits);
    sum.extend(frame, in.points.data()[row + first]);
    sum.extend(frame, in.points.data()[row + last]);
  });
  const Eigen::Vector3d& n = in.planes[plane].normal;
  // sum (n . p + offset)^2 with p = origin + q: n^T (sum q q^T) n + 2 e n . (sum q) + count e^2.
  const double e = n.dot(in.origin) + in.planes[plane].offset;
  sum.squared_error += n.dot(m.sum_outer * n) + 2 * e * n.dot(m.sum) + double(m.count) * e * e;
  sum.count += m.count;
}

bool at_image_edge(const CellGrid& cells, std::size_t cell) {
  const std::size_t cx = cell % cells.columns, cy = cell / cells.columns;
  return cx == 0 || cy == 0 || cx + 1 == std::size_t(cells.columns) ||
         cy + 1 == std::size_t(cells.rows);
}

// The candidates' coefficients, each in all four lanes.
CandidateLanes candidate_lanes(const AssignInputs& in, const CellCandidates& candidates) {
  CandidateLanes lanes;
  lanes.count = candidates.count;
  for (int k = 0; k < candidates.count; ++k) {
    const ScoredPlane& plane = in.scored[candidates.planes[k]];
    lanes.nx[k] = splat(plane.normal.x()), lanes.ny[k] = splat(plane.normal.y());
    lanes.nz[k] = splat(plane.normal.z()), lanes.offset[k] = splat(plane.offset);
  }
  return lanes;
}

// The points at x .. x + 3 of a row as lanes (NaN past `end`, and where there is no point).
PixelLanes pixel_lanes(const Point4f* row, int x, int end) {
  const compute::detail::XyzLanes t = compute::detail::load_xyz(row[x].data(), end - x);
  return {t.x, t.y, t.z};
}

// The device's choices for the pixels at x .. x + 3 of row y of job `job` (rectangle `rect`), as
// ScoreRule::best gives them (-1: none, also past the rectangle).
LaneMask device_choices(const ScoringJobs& scores, std::size_t job, const PixelRect& rect, int x,
                        int y, Lanes& distance2) {
  const std::size_t first = scores.slot(job) +
                            static_cast<std::size_t>(y - rect.y0) * (rect.x1 - rect.x0) +
                            static_cast<std::size_t>(x - rect.x0);
  LaneMask choices = splat(-1);
  distance2 = splat(1.0f);
  for (int j = 0; j < 4 && x + j < rect.x1; ++j) {
    // KG_CELL_NO_CHOICE is -1 as a signed lane.
    choices[j] = static_cast<std::int32_t>(scores.choices[first + j]);
    distance2[j] = scores.distances[first + j];
  }
  return choices;
}

// The choices of a rectangle's pixels, row by row: the device's (off the CPU backend), else the
// rule's on the host, eight pixels at a time (cell_scores_wide.hpp, the same choices) where the
// processor has AVX2 and the width is a multiple of eight, four at a time otherwise.
class RectChoices {
 public:
  RectChoices(const AssignInputs& in, const PixelRect& rect, const CellCandidates& candidates,
              std::size_t job)
      : in_(in), rect_(rect), job_(job) {
    const int width = rect.x1 - rect.x0;
    wide_ =
        !in.device && width % 8 == 0 && width <= kMaxWidth && compute::detail::wide_lanes_enabled();
    if (in.device) return;
    if (!wide_) {
      lanes_ = candidate_lanes(in, candidates);
      return;
    }
    for (int k = 0; k < candidates.count; ++k) {
      const ScoredPlane& plane = in.scored[candidates.planes[k]];
      nx_[k] = plane.normal.x(), ny_[k] = plane.normal.y(), nz_[k] = plane.normal.z();
      offset_[k] = plane.offset;
    }
    wide_in_ = {in.rule.distance_base,
                in.rule.distance_per_z2,
                in.rule.min_facing,
                nx_.data(),
                ny_.data(),
                nz_.data(),
                offset_.data(),
                candidates.count};
  }

  // Row y is next (`row`: the image row's first point, `stride`: points from row to row). The
  // wide path chooses for kBatchRows rows at once.
  void start_row(const Point4f* row, int y, int stride) {
    if (!wide_) return;
    const int width = rect_.x1 - rect_.x0;
    batch_offset_ = (y - rect_.y0) % kBatchRows * width;
    if (batch_offset_ == 0) {
      wide_rows_choices(wide_in_, row, stride, std::min(kBatchRows, rect_.y1 - y), rect_.x0,
                        rect_.x1, choices_.data(), distances_.data());
    }
  }

  bool wide() const { return wide_; }

  // The wide path's row (after start_row): per candidate k, the pixels that took it as bits from
  // the rectangle's first column, and their squared distances' sum; each pixel's plane written
  // to `pixel_row` (the rectangle's first pixel of the row in pixel_plane, none taken before).
  void tally_row(const CellCandidates& candidates, std::array<std::uint64_t, 36>& bits,
                 std::array<float, 36>& squared, std::uint32_t* pixel_row) const {
    const int width = rect_.x1 - rect_.x0;
    const std::int32_t* choices = choices_.data() + batch_offset_;
    wide_row_tally(choices, distances_.data() + batch_offset_, width, candidates.count, bits.data(),
                   squared.data());
    std::array<std::uint32_t, 37> plane_of;  // of a choice + 1 (0: none)
    plane_of[0] = geometry::kNoLabel;
    std::copy_n(candidates.planes.begin(), candidates.count, plane_of.begin() + 1);
    for (int j = 0; j < width; ++j) pixel_row[j] = plane_of[choices[j] + 1];
  }

  // The four-lane path (not wide()): the pixels x .. x + 3 of row y (`row` its first point),
  // their choices (-1: none) and squared distances.
  LaneMask at(const Point4f* row, int x, int y, Lanes& distance2) const {
    if (in_.device) return device_choices(*in_.device, job_, rect_, x, y, distance2);
    return in_.rule.best(lanes_, pixel_lanes(row, x, rect_.x1), distance2);
  }

 private:
  static constexpr int kMaxWidth = 64;  // a cell's largest side
  static constexpr int kBatchRows = 8;
  const AssignInputs& in_;
  PixelRect rect_;
  std::size_t job_;
  bool wide_ = false;
  CandidateLanes lanes_;
  std::array<float, 36> nx_, ny_, nz_, offset_;
  WideScoreInputs wide_in_{};
  int batch_offset_ = 0;  // the row's first entry in the batch's choices
  std::array<std::int32_t, kMaxWidth * kBatchRows> choices_;
  std::array<float, kMaxWidth * kBatchRows> distances_;
};

// A cell's pixels taken per candidate while it is scored: counts and squared distances for the
// cell, and per row the first and last pixel (x) that took each candidate.
struct CellTally {
  std::array<std::uint32_t, 36> taken{};
  std::array<double, 36> squared{};
  std::array<int, 36> first, last;

  // Four pixels from x whose lanes chose `choices` (-1: none).
  void add(const LaneMask& choices, const Lanes& distance2, int x) {
    const int c = choices[0];
    const LaneMask differ = choices ^ splat(c);
    if (c >= 0 && (differ[0] | differ[1] | differ[2] | differ[3]) == 0) {  // the usual case
      taken[c] += 4;
      for (int j = 0; j < 4; ++j) squared[c] += distance2[j];
      if (first[c] < 0) first[c] = x;
      last[c] = x + 3;
      return;
    }
    for (int j = 0; j < 4; ++j) {
      const int choice = choices[j];
      if (choice < 0) continue;
      ++taken[choice];
      squared[choice] += distance2[j];
      if (first[choice] < 0) first[choice] = x + j;
      last[choice] = x + j;
    }
  }

  // A whole row from the wide path (RectChoices::tally_row), its first column at x0.
  void add_row(const RectChoices& source, const CellCandidates& candidates, int x0,
               std::uint32_t* pixel_row) {
    std::array<std::uint64_t, 36> bits;
    std::array<float, 36> row_squared;
    source.tally_row(candidates, bits, row_squared, pixel_row);
    for (int k = 0; k < candidates.count; ++k) {
      if (bits[k] == 0) continue;
      taken[k] += static_cast<std::uint32_t>(std::popcount(bits[k]));
      squared[k] += row_squared[k];
      first[k] = x0 + std::countr_zero(bits[k]);
      last[k] = x0 + 63 - std::countl_zero(bits[k]);
    }
  }
};

// Each valid pixel of the rectangle (a cell or a block) takes the candidate it scores best
// against (none if none is within its allowance), and is added to that plane's sums: its count
// and squared distance, and its extent from the first and last pixel of each row that took the
// plane (the corners of the hull of a plane's pixels in the rectangle are among them; see
// assign_whole). Four pixels are scored at once on the host, or their scores read from the
// device's (`job`: the rectangle's scoring job); the sums stay in locals until the rectangle is
// done. Returns how many pixels took each candidate.
std::array<std::uint32_t, 36> score_pixels(const AssignInputs& in, const PixelRect& rect,
                                           const CellCandidates& candidates, std::size_t job,
                                           std::vector<PlanePixelSums>& sums,
                                           std::vector<std::uint32_t>& pixel_plane) {
  const Point4f* points = in.points.data();
  const auto [x0, y0, x1, y1] = rect;
  const int count = candidates.count;
  RectChoices source(in, rect, candidates, job);
  CellTally tally;
  for (int y = y0; y < y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * in.points.width();
    // The next row's points, a row of the image away, fetched while this one is scored (the wide
    // path chooses for eight rows at once: for it this readies the next batch's first row).
    if (y + 1 < y1) {
      const Point4f* next = points + row + in.points.width();
      compute::detail::prefetch_lines(next + x0, next + x1);
    }
    std::fill_n(tally.first.begin(), count, -1);
    source.start_row(points + row, y, in.points.width());
    if (source.wide()) {
      tally.add_row(source, candidates, x0, pixel_plane.data() + row + x0);
    } else {
      for (int x = x0; x < x1; x += 4) {
        Lanes distance2;
        const LaneMask choices = source.at(points + row, x, y, distance2);
        for (int j = 0; j < 4; ++j) {
          if (choices[j] >= 0) pixel_plane[row + x + j] = candidates.planes[choices[j]];
        }
        tally.add(choices, distance2, x);
      }
    }
    for (int k = 0; k < count; ++k) {
      if (tally.first[k] < 0) continue;
      const std::uint32_t plane = candidates.planes[k];
      sums[plane].extend(in.frames[plane], points[row + tally.first[k]]);
      sums[plane].extend(in.frames[plane], points[row + tally.last[k]]);
    }
  }
  for (int k = 0; k < count; ++k) {
    sums[candidates.planes[k]].count += tally.taken[k];
    sums[candidates.planes[k]].squared_error += tally.squared[k];
  }
  return tally.taken;
}

// What a cell's assignment leaves: the plane it carries on to the next passes (kNoLabel: none)
// and how many of its valid pixels took no plane.
struct CellOutcome {
  std::uint32_t carried;
  std::uint32_t left;
};

// The candidates of block b of a planar cell in plane `own`: its plane and the planes of the
// eight blocks around it (pass 0's); `whole` when they are all its plane and none lies past the
// image's edge.
CellCandidates block_candidates(const AssignInputs& in, std::size_t cell, int b,
                                std::uint32_t own) {
  const CellGrid& cells = in.cells;
  const int bx = static_cast<int>(cell % cells.columns) * 2 + b % 2;
  const int by = static_cast<int>(cell / cells.columns) * 2 + b / 2;
  CellCandidates out;
  out.add(own);
  out.own = out.whole = true;
  for (int y = by - 1; y <= by + 1; ++y) {
    for (int x = bx - 1; x <= bx + 1; ++x) {
      if (x < 0 || y < 0 || x >= 2 * cells.columns || y >= 2 * cells.rows) {
        out.whole = false;
        continue;
      }
      const std::size_t c = static_cast<std::size_t>(y / 2) * cells.columns + x / 2;
      const std::uint32_t plane = (*in.block_planes)[c][(y % 2) * 2 + x % 2];
      out.whole = out.whole && plane == own;
      out.add(plane);
    }
  }
  return out;
}

// The parts of a cell's assignment, in the order it meets them: whole(rect, moments, inside) for
// a rectangle whose valid pixels take the cell's own plane, scored(rect, candidates) for one whose
// pixels are scored among candidates. A planar cell with no other plane around is one whole part;
// a planar cell beside other planes goes block by block (a block with no other plane among its 8
// neighbouring blocks is whole; the others are scored among those blocks' planes, so a pixel of a
// planar cell takes another plane only from a block next to its own: the cell's fit and
// planarity test have judged all its pixels but a border's); any other cell is scored whole.
template <class Whole, class Scored>
void for_each_part(const AssignInputs& in, std::size_t cell, const CellCandidates& candidates,
                   Whole&& whole, Scored&& scored) {
  if (!candidates.own) {
    scored(cell_rect(in, cell), candidates);
    return;
  }
  if (candidates.count == 1) {
    whole(cell_rect(in, cell), in.cells.moments[cell],
          candidates.whole && !at_image_edge(in.cells, cell));
    return;
  }
  for (int b = 0; b < 4; ++b) {
    const PixelRect rect = block_rect(in, cell, b);
    if (rect.x0 >= rect.x1 || rect.y0 >= rect.y1) continue;
    const CellCandidates block = block_candidates(in, cell, b, candidates.planes[0]);
    if (block.count == 1) {
      whole(rect, in.cells.block_moments[4 * cell + b], block.whole);
    } else {
      scored(rect, block);
    }
  }
}

// Assigns the cell's valid pixels among the candidates, adding them to their planes' sums;
// returns the plane that took the most of them when that is at least a quarter of the cell's
// valid pixels (kNoLabel otherwise). `job`: the cell's first scoring job (add_scoring_jobs').
CellOutcome assign_cell(const AssignInputs& in, std::size_t cell, const CellCandidates& candidates,
                        std::size_t job, std::vector<PlanePixelSums>& sums,
                        std::vector<std::uint32_t>& pixel_plane) {
  std::array<std::uint32_t, 36> taken{};  // per candidate of the cell
  const auto whole = [&](const PixelRect& rect, const geometry::SegmentMoments& m, bool inside) {
    assign_whole(in, rect, m, candidates.planes[0], inside, sums, pixel_plane);
    taken[0] += static_cast<std::uint32_t>(m.count);
  };
  const auto scored = [&](const PixelRect& rect, const CellCandidates& part) {
    const std::array<std::uint32_t, 36> part_taken =
        score_pixels(in, rect, part, job++, sums, pixel_plane);
    for (int k = 0; k < part.count; ++k) {
      const auto* at = std::find(candidates.planes.begin(),
                                 candidates.planes.begin() + candidates.count, part.planes[k]);
      taken[static_cast<std::size_t>(at - candidates.planes.begin())] += part_taken[k];
    }
  };
  for_each_part(in, cell, candidates, whole, scored);
  const auto most =
      std::max_element(taken.begin(), taken.begin() + candidates.count) - taken.begin();
  const std::uint64_t valid = in.cells.moments[cell].count;
  const bool enough = candidates.count > 0 && 4 * taken[most] >= valid;
  const auto left = static_cast<std::uint32_t>(
      valid - std::accumulate(taken.begin(), taken.begin() + candidates.count, std::uint64_t{0}));
  return {enough ? candidates.planes[most] : geometry::kNoLabel, left};
}

void add_job(const PixelRect& rect, const CellCandidates& candidates, ScoringJobs& jobs) {
  const auto area = static_cast<std::size_t>(rect.x1 - rect.x0) * (rect.y1 - rect.y0);
  const std::uint32_t words[KG_CELL_JOB_WORDS] = {
      static_cast<std::uint32_t>(rect.x0),
      static_cast<std::uint32_t>(rect.y0),
      static_cast<std::uint32_t>(rect.x1),
      static_cast<std::uint32_t>(rect.y1),
      static_cast<std::uint32_t>(jobs.candidates.size()),
      static_cast<std::uint32_t>(candidates.count),
      static_cast<std::uint32_t>(jobs.pixels)};
  jobs.words.insert(jobs.words.end(), words, words + KG_CELL_JOB_WORDS);
  jobs.candidates.insert(jobs.candidates.end(), candidates.planes.begin(),
                         candidates.planes.begin() + candidates.count);
  jobs.pixels += area;
}

// The cell's scoring jobs, in the order assign_cell meets them.
void add_scoring_jobs(const AssignInputs& in, std::size_t cell, const CellCandidates& candidates,
                      ScoringJobs& jobs) {
  for_each_part(
      in, cell, candidates, [](const PixelRect&, const geometry::SegmentMoments&, bool) {},
      [&](const PixelRect& rect, const CellCandidates& part) { add_job(rect, part, jobs); });
}

// `buffer` holding at least `count` values (grown by half again or more, so rarely).
template <class T>
compute::Buffer<T>& at_least(compute::Buffer<T>& buffer, const compute::Context& context,
                             std::size_t count) {
  if (buffer.size() < count)
    buffer = compute::Buffer<T>(context, std::max(count, buffer.size() * 3 / 2));
  return buffer;
}

// The jobs' pixels scored on the context's backend (kernels/cell_scores); buffers.score_planes
// holds the planes (n, offset).
void score_on_device(const compute::Context& context, const compute::Buffer<Point4f>& points,
                     CellBuffers& buffers, const AssignInputs& in, ScoringJobs& jobs) {
  jobs.choices.resize(jobs.pixels);
  jobs.distances.resize(jobs.pixels);
  if (jobs.pixels == 0) return;
  at_least(buffers.score_jobs, context, jobs.words.size()).upload(jobs.words);
  at_least(buffers.score_candidates, context, jobs.candidates.size()).upload(jobs.candidates);
  at_least(buffers.score_choices, context, jobs.pixels);
  at_least(buffers.score_distances, context, jobs.pixels);
  const auto job_count = static_cast<std::uint32_t>(jobs.words.size() / KG_CELL_JOB_WORDS);
  const kernels::CellScoresParams params{static_cast<std::uint32_t>(in.points.width()), job_count,
                                         in.rule.distance_base, in.rule.distance_per_z2,
                                         in.rule.min_facing};
  compute::dispatch(context, kCellScoresKernel,
                    {points, buffers.score_jobs, buffers.score_candidates, buffers.score_planes,
                     buffers.score_choices, buffers.score_distances},
                    params, {compute::groups_for(job_count, kCellScoresKernel.local_x)});
  buffers.score_choices.download(jobs.choices);
  buffers.score_distances.download(jobs.distances);
}

// Off the CPU backend, each pass's pixels are scored by the device (the CPU backend scores them
// four at a time as the cells are assigned): the planes go up once, each pass's jobs go up and
// their choices come back.
class DeviceScoring {
 public:
  DeviceScoring(const compute::Context& context, const compute::Buffer<Point4f>& points,
                CellBuffers& buffers, const AssignInputs& in)
      : context_(&context), points_(&points), buffers_(&buffers) {
    std::vector<Eigen::Vector4f> planes;
    for (const ScoredPlane& plane : in.scored) {
      planes.emplace_back(plane.normal.x(), plane.normal.y(), plane.normal.z(), plane.offset);
    }
    if (!planes.empty()) at_least(buffers.score_planes, context, planes.size()).upload(planes);
  }

  // The pass's cells' jobs scored (in.device then points to them); each cell's first job.
  std::vector<std::size_t> score(AssignInputs& in, const std::vector<std::size_t>& cells,
                                 const std::vector<CellCandidates>& candidates) {
    jobs_ = ScoringJobs{};
    std::vector<std::size_t> first_job(cells.size());
    for (std::size_t k = 0; k < cells.size(); ++k) {
      first_job[k] = jobs_.words.size() / KG_CELL_JOB_WORDS;
      add_scoring_jobs(in, cells[k], candidates[k], jobs_);
    }
    score_on_device(*context_, *points_, *buffers_, in, jobs_);
    in.device = &jobs_;
    return first_job;
  }

 private:
  const compute::Context* context_;
  const compute::Buffer<Point4f>* points_;
  CellBuffers* buffers_;
  ScoringJobs jobs_;
};

AssignInputs assign_inputs(const PointImage& points, const CellGrid& cells,
                           const std::vector<SegmentPlane>& planes, const Eigen::Vector3d& origin,
                           const PlaneMergeParams& params) {
  AssignInputs in{points, cells, planes, origin, {}, {}, {}};
  for (const SegmentPlane& plane : planes) {
    in.scored.push_back({plane.normal.cast<float>(), static_cast<float>(plane.offset)});
    in.frames.push_back(PlaneFrame::of(plane));
  }
  in.rule = {static_cast<float>(params.distance_base), static_cast<float>(params.distance_per_z2),
             static_cast<float>(params.min_facing_factor)};
  return in;
}

}  // namespace

std::vector<PlanePixelSums> assign_cell_pixels(
    const compute::Context& context, const compute::Buffer<Point4f>& device_points,
    CellBuffers& buffers, const PointImage& points, const CellGrid& cells,
    const std::vector<std::uint32_t>& segment_plane, const std::vector<SegmentPlane>& planes,
    const Eigen::Vector3d& origin, const PlaneMergeParams& params, int passes,
    std::vector<std::uint32_t>& pixel_plane, std::vector<std::uint32_t>& open_cells) {
  constexpr std::uint32_t kNone = geometry::kNoLabel;
  using Planes = std::array<std::uint32_t, 4>;
  AssignInputs in = assign_inputs(points, cells, planes, origin, params);
  pixel_plane.assign(points.size(), kNone);
  // Per cell: its segments' planes; the pass that assigned it (-1: none yet); the plane it
  // carries on to the next passes' cells (the one most of its pixels took).
  std::vector<Planes> cell_planes(cells.size(), {kNone, kNone, kNone, kNone});
  for (std::size_t c = 0; c < cells.size(); ++c) {
    for (std::size_t b = 0; b < 4; ++b) {
      const std::uint32_t s = cells.segments[c][b];
      if (s != kNone) cell_planes[c][b] = segment_plane[s];
    }
  }
  in.block_planes = &cell_planes;
  std::optional<DeviceScoring> device;
  if (!context.is_cpu()) device.emplace(context, device_points, buffers, in);
  std::vector<int> assigned_in(cells.size(), -1);
  std::vector<std::uint32_t> carried(cells.size(), kNone);
  std::vector<std::uint32_t> left(cells.size());
  std::vector<PlanePixelSums> total(planes.size());
  std::array<std::vector<PlanePixelSums>, compute::detail::kCpuChunks> chunk_sums;
  for (int pass = 0; pass < std::max(1, passes); ++pass) {
    const auto planes_of = [&](std::size_t c) {
      if (pass == 0) return cell_planes[c];
      const bool earlier = assigned_in[c] >= 0 && assigned_in[c] < pass;
      return Planes{earlier ? carried[c] : kNone, kNone, kNone, kNone};
    };
    // The cells this pass reaches, with their candidates (found once).
    std::vector<std::size_t> now;
    std::vector<CellCandidates> now_candidates;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (assigned_in[c] >= 0) continue;
      const CellCandidates candidates = candidates_of(cells, c, planes_of);
      if (candidates.count == 0) continue;
      now.push_back(c);
      now_candidates.push_back(candidates);
    }
    if (now.empty()) break;
    // The device scores the first pass, which holds nearly all the scored pixels; the few cells
    // the later passes reach are scored on the host (the same rule, bit for bit).
    const bool on_device = device && pass == 0;
    in.device = nullptr;
    const std::vector<std::size_t> first_job =
        on_device ? device->score(in, now, now_candidates) : std::vector<std::size_t>{};
    compute::detail::for_each_chunk(
        now.size(), now.size() * static_cast<std::size_t>(cells.cell_size * cells.cell_size),
        [&](std::size_t begin, std::size_t end, std::size_t chunk) {
          chunk_sums[chunk].assign(planes.size(), PlanePixelSums{});
          for (std::size_t k = begin; k < end; ++k) {
            const std::size_t c = now[k];
            const CellOutcome outcome =
                assign_cell(in, c, now_candidates[k], on_device ? first_job[k] : 0,
                            chunk_sums[chunk], pixel_plane);
            carried[c] = outcome.carried, left[c] = outcome.left;
          }
        });
    for (const std::vector<PlanePixelSums>& sums : chunk_sums) {  // in chunk order
      for (std::size_t m = 0; m < sums.size(); ++m) total[m].add(sums[m]);
    }
    for (const std::size_t c : now) assigned_in[c] = pass;
  }
  open_cells.clear();
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (assigned_in[c] < 0 ? cells.moments[c].count > 0 : left[c] > 0)
      open_cells.push_back(static_cast<std::uint32_t>(c));
  }
  return total;
}

}  // namespace kartograf::segmentation::detail
