#include "kartograf/mapping/tsdf_slice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kartograf/geometry/distance_transform.hpp"
#include "kernels/esdf/esdf.h"
#include "kernels/tsdf/tsdf_band.h"
#include "mapping/esdf_lines.hpp"

namespace kartograf::mapping {

namespace {

constexpr compute::KernelSpec kBandKernel{"tsdf_band", KG_TSDF_LOCAL_X, 1};
constexpr compute::KernelSpec kEsdfSeedKernel{"esdf_seed", KG_ESDF_LOCAL_X, 1};
constexpr compute::KernelSpec kEsdfWriteKernel{"esdf_write", KG_ESDF_LOCAL_X, 1};
static_assert(KG_ESDF_OCCUPIED == KG_TSDF_BAND_OCCUPIED);

// The centres of the surface voxels, in the level frame.
std::vector<Eigen::Vector3d> surface_points(const TsdfBlocks& blocks,
                                            const TsdfSliceParams& params) {
  std::vector<Eigen::Vector3d> out;
  const double near = blocks.voxel_size / blocks.truncation;  // one voxel, in tsdf units
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (std::size_t i = 0; i < kTsdfBlockVoxels; ++i) {
      const TsdfVoxel& v = blocks.voxels[b * kTsdfBlockVoxels + i];
      if (v.weight < params.min_weight || v.tsdf >= near) continue;
      const Eigen::Vector3i local(static_cast<int>(i % 8), static_cast<int>(i / 8 % 8),
                                  static_cast<int>(i / 64));
      const Eigen::Vector3d centre =
          ((blocks.coords[b] * kTsdfBlockSide + local).cast<double>().array() + 0.5) *
          blocks.voxel_size;
      out.push_back(params.world_to_level * centre);
    }
  }
  return out;
}

// An empty grid (all unknown) over the footprint of the blocks' voxel centres in the level frame.
OccupancyGrid band_grid(const std::vector<Eigen::Vector3i>& coords, double voxel_size,
                        const TsdfSliceParams& params) {
  OccupancyGrid grid;
  grid.resolution = params.resolution;
  if (coords.empty()) return grid;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const Eigen::Vector3i& b : coords) {
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3i offset((corner & 1) * 7, ((corner >> 1) & 1) * 7, (corner >> 2) * 7);
      const Eigen::Vector3d centre =
          ((b * kTsdfBlockSide + offset).cast<double>().array() + 0.5) * voxel_size;
      const Eigen::Vector2d p = (params.world_to_level * centre).head<2>();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  // Half a cell of margin: cell edges then fall between voxel centres for the usual sizes (1, 2,
  // 4, 5 cm voxels, 5 cm cells) instead of on every few of them.
  lo -= Eigen::Vector2d::Constant(params.resolution / 2);
  const auto cols = static_cast<int>(std::floor((hi.x() - lo.x()) / params.resolution)) + 1;
  const auto rows = static_cast<int>(std::floor((hi.y() - lo.y()) / params.resolution)) + 1;
  require(static_cast<double>(cols) * rows <= 1e8, "TSDF slice: the grid would exceed 1e8 cells");
  grid.origin = Eigen::Vector3d(lo.x(), lo.y(), 0);
  grid.cells = Image<CellState>(cols, rows, CellState::unknown);
  return grid;
}

kernels::TsdfBandParams band_params(const TsdfVolumeParams& volume, const OccupancyGrid& grid,
                                    const TsdfSliceParams& params, std::size_t blocks) {
  kernels::TsdfBandParams p{};
  const Eigen::Matrix3d r = params.world_to_level.linear();
  const Eigen::Vector3d t = params.world_to_level.translation();
  float* rotation[] = {&p.r00, &p.r01, &p.r02, &p.r10, &p.r11, &p.r12, &p.r20, &p.r21, &p.r22};
  for (int k = 0; k < 9; ++k) *rotation[k] = static_cast<float>(r(k / 3, k % 3));
  p.tx = static_cast<float>(t.x()), p.ty = static_cast<float>(t.y()),
  p.tz = static_cast<float>(t.z());
  p.voxel_size = static_cast<float>(volume.voxel_size);
  p.near = static_cast<float>(volume.voxel_size / volume.truncation);
  p.min_weight = params.min_weight;
  p.floor_z = static_cast<float>(params.floor_z);
  p.floor_tolerance = static_cast<float>(params.floor_tolerance);
  p.band_min = static_cast<float>(params.band_min);
  p.band_max = static_cast<float>(params.band_max);
  p.origin_x = static_cast<float>(grid.origin.x());
  p.origin_y = static_cast<float>(grid.origin.y());
  p.inverse_resolution = static_cast<float>(1.0 / params.resolution);
  p.cols = static_cast<std::uint32_t>(grid.width());
  p.rows = static_cast<std::uint32_t>(grid.height());
  p.count = static_cast<std::uint32_t>(blocks * kTsdfBlockVoxels);
  return p;
}

}  // namespace

void TsdfSliceParams::validate() const {
  require(world_to_level.matrix().allFinite(), "TSDF slice: world_to_level is not finite");
  require(std::isfinite(floor_z) && floor_tolerance >= 0, "TSDF slice: bad floor_z or tolerance");
  require(band_min < band_max, "TSDF slice: band_min must be below band_max");
  require(resolution > 0 && std::isfinite(resolution), "TSDF slice: resolution must be > 0");
}

OccupancyGrid tsdf_occupancy(const TsdfBlocks& blocks, const TsdfSliceParams& params) {
  params.validate();
  OccupancyGrid grid = band_grid(blocks.coords, blocks.voxel_size, params);
  if (grid.width() == 0) return grid;
  for (const Eigen::Vector3d& p : surface_points(blocks, params)) {
    const double h = p.z() - params.floor_z;
    const bool in_band = h >= params.band_min && h <= params.band_max;
    const bool floor = std::abs(h) <= params.floor_tolerance;
    if (!in_band && !floor) continue;
    const Eigen::Vector2i cell = grid.cell_of(p.head<2>());
    if (!grid.contains(cell)) continue;
    CellState& state = grid.cells(cell.x(), cell.y());
    if (in_band)
      state = CellState::occupied;
    else if (state == CellState::unknown)
      state = CellState::free;
  }
  return grid;
}

namespace {

// The band's grid over the volume's blocks (cells still unknown) and its marks on the device.
compute::Buffer<std::uint32_t> band_cells(const TsdfVolume& volume, const TsdfSliceParams& params,
                                          OccupancyGrid& grid) {
  params.validate();
  const std::size_t n = std::min(volume.block_count(), volume.params().max_blocks);
  std::vector<std::uint64_t> keys(n);
  if (n > 0) volume.device_block_keys().download(keys);
  std::vector<Eigen::Vector3i> coords;
  for (const std::uint64_t key : keys)
    coords.emplace_back(kernels::tsdf_key_axis(key, 0), kernels::tsdf_key_axis(key, 21),
                        kernels::tsdf_key_axis(key, 42));
  grid = band_grid(coords, volume.params().voxel_size, params);
  const compute::Context& context = volume.context();
  compute::Buffer<std::uint32_t> cells(context, std::max<std::size_t>(grid.cells.size(), 1));
  cells.fill_zero();
  if (grid.width() == 0) return cells;
  const kernels::TsdfBandParams p = band_params(volume.params(), grid, params, n);
  compute::dispatch(context, kBandKernel,
                    {volume.device_block_keys(), volume.device_voxels(), cells}, p,
                    {compute::groups_for(p.count, KG_TSDF_LOCAL_X), 1});
  return cells;
}

void set_states(const std::vector<std::uint32_t>& marks, OccupancyGrid& grid) {
  for (std::size_t i = 0; i < grid.cells.size(); ++i) {
    grid.cells.pixels()[i] = marks[i] == KG_TSDF_BAND_OCCUPIED ? CellState::occupied
                             : marks[i] == KG_TSDF_BAND_FREE   ? CellState::free
                                                               : CellState::unknown;
  }
}

// One transform of kernels/esdf/esdf.h (to the occupied cells or to the others) into `esdf`.
void esdf_transform(const compute::Context& context, const compute::Buffer<std::uint32_t>& cells,
                    int cols, int rows, kernels::EsdfParams p, detail::EsdfScratch& scratch,
                    compute::Buffer<float>& esdf) {
  const std::size_t n = std::size_t(cols) * rows;
  p.count = static_cast<std::uint32_t>(n);
  compute::dispatch(context, kEsdfSeedKernel, {cells, scratch.a}, p,
                    {compute::groups_for(n, KG_ESDF_LOCAL_X), 1});
  const auto plane = [](std::size_t count, std::size_t length, std::size_t line_stride,
                        std::size_t cell_stride) {
    return detail::EsdfLines{count, length, line_stride, count, 0, cell_stride};
  };
  detail::esdf_envelope(plane(cols, rows, 1, cols), scratch.a, scratch.b, scratch);  // columns
  detail::esdf_envelope(plane(rows, cols, cols, 1), scratch.b, scratch.a, scratch);  // rows
  compute::dispatch(context, kEsdfWriteKernel, {scratch.a, cells, esdf}, p,
                    {compute::groups_for(n, KG_ESDF_LOCAL_X), 1});
}

// The ESDF of a grid of band marks (row-major, cols x rows) on their device.
Image<float> device_esdf(const compute::Context& context,
                         const compute::Buffer<std::uint32_t>& cells, int cols, int rows,
                         double resolution) {
  const double cells_count = static_cast<double>(cols) * rows;
  require(cells_count < 4294967296.0, "ESDF: a grid of 2^32 cells or more");
  // Per cell: the result, two squared distances and the envelope's apex and crossing.
  require_fits_in_memory(
      cells_count * (4 + detail::kEsdfScratchBytesPerCell),
      "ESDF of a " + std::to_string(cols) + "x" + std::to_string(rows) + " grid");
  Image<float> out(cols, rows);
  if (out.empty()) return out;
  compute::Buffer<float> esdf(context, out.pixels().size());
  esdf.fill_zero();
  kernels::EsdfParams p{};
  p.resolution = static_cast<float>(resolution);
  detail::EsdfScratch scratch(context);
  scratch.reserve(out.pixels().size());
  for (const std::uint32_t to_occupied : {1u, 0u}) {
    p.to_occupied = to_occupied;
    esdf_transform(context, cells, cols, rows, p, scratch, esdf);
  }
  esdf.download(out.pixels());
  return out;
}

}  // namespace

OccupancyGrid tsdf_occupancy(const TsdfVolume& volume, const TsdfSliceParams& params) {
  OccupancyGrid grid;
  const compute::Buffer<std::uint32_t> cells = band_cells(volume, params, grid);
  if (grid.width() > 0) set_states(cells.to_vector(), grid);
  return grid;
}

TsdfBandMaps tsdf_band_maps(const TsdfVolume& volume, const TsdfSliceParams& params) {
  TsdfBandMaps maps;
  const compute::Buffer<std::uint32_t> cells = band_cells(volume, params, maps.occupancy);
  if (maps.occupancy.width() == 0) return maps;
  set_states(cells.to_vector(), maps.occupancy);
  maps.esdf = device_esdf(volume.context(), cells, maps.occupancy.width(), maps.occupancy.height(),
                          maps.occupancy.resolution);
  return maps;
}

Image<float> occupancy_esdf(const compute::Context& context, const OccupancyGrid& grid) {
  std::vector<std::uint32_t> marks(grid.cells.size());
  for (std::size_t i = 0; i < marks.size(); ++i) {
    const CellState state = grid.cells.pixels()[i];
    marks[i] = state == CellState::occupied ? KG_TSDF_BAND_OCCUPIED
               : state == CellState::free   ? KG_TSDF_BAND_FREE
                                            : 0u;
  }
  if (marks.empty()) return Image<float>(grid.width(), grid.height());
  const auto cells = compute::Buffer<std::uint32_t>::from_host(context, marks);
  return device_esdf(context, cells, grid.width(), grid.height(), grid.resolution);
}

Image<float> occupancy_esdf(const OccupancyGrid& grid) {
  const int w = grid.width(), h = grid.height();
  Image<std::uint8_t> to_obstacle(w, h), to_outside(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool occupied = grid.cells(x, y) == CellState::occupied;
      to_obstacle(x, y) = occupied ? 0 : 1;
      to_outside(x, y) = occupied ? 1 : 0;
    }
  }
  const Image<float> outside = geometry::distance_to_zero(to_obstacle);
  const Image<float> inside = geometry::distance_to_zero(to_outside);
  Image<float> esdf(w, h);
  const auto r = static_cast<float>(grid.resolution);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool occupied = grid.cells(x, y) == CellState::occupied;
      esdf(x, y) = occupied ? -r * inside(x, y) : r * outside(x, y);
    }
  }
  return esdf;
}

}  // namespace kartograf::mapping
