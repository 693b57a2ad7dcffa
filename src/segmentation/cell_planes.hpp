#pragma once
// The cells mode of plane extraction (plane_extraction.hpp, PlaneExtractionMode::cells): the
// image cut into square cells, each cell's moments and depth continuity measured in one pass, the
// planar cells as the segments that merging joins, and pixels assigned cell by cell.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/segment_moments.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/segmentation/plane_merge.hpp"
#include "kartograf/segmentation/region_growing.hpp"
#include "kartograf/segmentation/segment_graph.hpp"
#include "plane_output.hpp"

namespace kartograf::segmentation::detail {

// Cells of cell_size pixels a side, each made of 2 x 2 blocks (half a cell a side): a cell
// that is not planar as a whole may still hold planar blocks (a strip of table between objects).
struct CellGrid {
  int cell_size = 0;
  int width = 0, height = 0;  // the image's, in pixels
  int columns = 0, rows = 0;  // cells across and down (the last ones may be cut by the border)
  std::vector<geometry::SegmentMoments> moments;  // per cell, about the moment origin
  std::vector<std::uint8_t> continuous;           // per cell: no edge's depth jump across it
  // Per block (cell c's blocks are 4 c .. 4 c + 3, row by row; absent ones are empty).
  std::vector<geometry::SegmentMoments> block_moments;
  std::vector<std::uint8_t> block_continuous;
  std::vector<Eigen::Vector3d> block_colours;  // sum of the block's valid pixels' RGB
  // Which pixels have a point: per block of the image's block grid (blocks_x across), mask_words
  // words of bits, row by row (bit (y - y0) half + x - x0).
  std::vector<std::uint32_t> block_masks;
  int blocks_x = 0, mask_words = 0;
  // Per cell: its segment in all four entries if the whole cell is planar, else those of its
  // planar blocks (kNoLabel where none).
  std::vector<std::array<std::uint32_t, 4>> segments;

  std::size_t size() const { return moments.size(); }
  int first_x(std::size_t cell) const { return static_cast<int>(cell % columns) * cell_size; }
  int first_y(std::size_t cell) const { return static_cast<int>(cell / columns) * cell_size; }
  // Bit k of the result: whether pixel (x0 + k, y0 + row) has a point, where (x0, y0) is the
  // first pixel of image block `block` (half a cell a side; row < half).
  std::uint32_t block_row_bits(std::size_t block, int row) const {
    const int half = cell_size / 2;
    const int bit = row * half;
    const std::uint32_t* words = block_masks.data() + block * mask_words + bit / 32;
    std::uint64_t v = words[0];
    if (bit % 32 + half > 32) v |= std::uint64_t{words[1]} << 32;
    return static_cast<std::uint32_t>((v >> (bit % 32)) & ((std::uint64_t{1} << half) - 1));
  }
  // The segment of block (bx, by) of the image's block grid (kNoLabel: none).
  std::uint32_t block_segment(int bx, int by) const {
    return segments[static_cast<std::size_t>(by / 2) * columns + bx / 2][(by % 2) * 2 + bx % 2];
  }
  // The segment pixel (x, y) lies in (kNoLabel: none).
  std::uint32_t segment_at(int x, int y) const {
    return block_segment(x / (cell_size / 2), y / (cell_size / 2));
  }
  // The same for pixel (x0 + k, y) of image block column `block_x` (y any row of the image).
  std::uint32_t valid_bits(int block_x, int y) const {
    const int half = cell_size / 2;
    return block_row_bits(static_cast<std::size_t>(y / half) * blocks_x + block_x, y % half);
  }
};

// One pass over the frame on the context's backend (kernels/cell_blocks): which pixels have a
// point, every block's moments about `origin` and colour sum, and every block's and cell's depth
// continuity: neighbouring valid pixels in a row or column of it jump (by more than
// max_depth_jump of their depth z and more than jump_per_z2 z^2) at most half its side's times
// (an edge across it jumps on each row or column it crosses). Cells sum their blocks.
void measure_cells(const compute::Context& context, const compute::Buffer<Point4f>& points,
                   const RgbImage& rgb, int cell_size, float max_depth_jump, float jump_per_z2,
                   const Eigen::Vector3d& origin, CellBuffers& buffers, CellGrid& cells);

// The segments of the cells mode, as merging takes them.
struct CellSegments {
  geometry::SegmentMomentSet moments;
  std::vector<SegmentPlane> fits;            // each one's fit (made to test its planarity)
  std::vector<Eigen::Vector3d> pixel_sums;   // each one's pixels: sum of x, sum of y, count
  std::vector<Eigen::Vector3f> lab_colours;  // each one's mean colour, CIE-Lab
};

// Planar cells, and the planar blocks of the other cells, become segments 0..n-1 (grid.segments;
// CellGrid::segment_at gives a pixel's). A cell or block is planar when enough of it is valid, its
// depth is continuous and its plane fit's RMS is within the noise allowance.
std::uint32_t planar_cell_segments(const CellPlaneParams& params, const PlaneMergeParams& merge,
                                   const Eigen::Vector3d& origin, CellGrid& cells,
                                   CellSegments& segments);

// The segments' neighbours (8-adjacent blocks of different segments), as merging takes them.
SegmentGraph cell_segment_graph(const CellGrid& cells, std::uint32_t segment_count);

// Every valid pixel's plane (index into `planes`, or kNoLabel), in passes over the cells:
// - first, planar cells whose neighbours hold no other plane take their plane whole, and the
//   other planar cells do the same block by block (a block beside another plane's block has its
//   pixels scored among its and its 8 neighbouring blocks' planes); pixels of the other cells
//   take, among the planes of their cell and its neighbours (those of their segments), the one
//   whose distance allowance they are deepest within (merge's plane score);
// - then (passes - 1 times) cells not yet reached do the same with the planes their reached
//   neighbours carry: the plane most of a cell's pixels took.
// Planes thus reach past the cells next to them, around objects and across gaps of no depth.
// segment_plane: each segment's plane (kNoLabel: none); origin: the cells' moments'. Returns the
// sums of each plane's pixels (cells and blocks taken whole add their moments' count and squared
// distances, and only their outline's pixels to the extent: see assign_whole); `open_cells`: the
// cells (in order) with valid pixels that no plane took. Off the CPU backend the first pass's
// pixels are scored on the context's device (kernels/cell_scores), from device_points (the frame's
// points there), with `buffers`' score buffers; the later passes' (few) and, on the CPU backend,
// all on the host, four at a time. The tallies (counts, squared distances, extents) and the passes'
// decisions stay on the host either way.
std::vector<PlanePixelSums> assign_cell_pixels(
    const compute::Context& context, const compute::Buffer<Point4f>& device_points,
    CellBuffers& buffers, const PointImage& points, const CellGrid& cells,
    const std::vector<std::uint32_t>& segment_plane, const std::vector<SegmentPlane>& planes,
    const Eigen::Vector3d& origin, const PlaneMergeParams& params, int passes,
    std::vector<std::uint32_t>& pixel_plane, std::vector<std::uint32_t>& open_cells);

}  // namespace kartograf::segmentation::detail
