#include "kartograf/mapping/esdf_volume.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kernels/esdf/esdf3.h"
#include "mapping/esdf_lines.hpp"

namespace kartograf::mapping {

namespace {

constexpr compute::KernelSpec kMarkKernel{"esdf3_mark", KG_ESDF_LOCAL_X, 1};
constexpr compute::KernelSpec kSeedKernel{"esdf3_seed", KG_ESDF_LOCAL_X, 1};
constexpr compute::KernelSpec kWriteKernel{"esdf3_write", KG_ESDF_LOCAL_X, 1};
constexpr double kGridBytesPerCell = 8;  // a mark and a distance

std::size_t volume_of(const Eigen::Vector3i& dims) {
  return dims.minCoeff() <= 0 ? 0 : std::size_t(dims.x()) * dims.y() * dims.z();
}

std::string cells_text(const Eigen::Vector3i& dims) {
  return std::to_string(dims.x()) + "x" + std::to_string(dims.y()) + "x" +
         std::to_string(dims.z()) + " cells";
}

int automatic_cell_voxels(double voxel_size) {
  for (const int s : {1, 2, 4}) {
    if (s * voxel_size >= 0.05 - 1e-9) return s;
  }
  return 8;
}

std::uint32_t narrow(std::size_t n) {
  return static_cast<std::uint32_t>(n);
}

}  // namespace

void EsdfVolumeParams::validate() const {
  require(cell_voxels == 0 || cell_voxels == 1 || cell_voxels == 2 || cell_voxels == 4 ||
              cell_voxels == 8,
          "ESDF: cell_voxels must be 0 (automatic), 1, 2, 4 or 8");
  require(std::isfinite(max_distance) && max_distance > 0, "ESDF: max_distance must be > 0");
  require(std::isfinite(min_weight) && min_weight >= 0, "ESDF: min_weight must be >= 0");
  require(std::isfinite(growth_m) && growth_m >= 0, "ESDF: growth_m must be >= 0");
  require(max_cells > 0 && max_cells < (std::size_t(1) << 32),
          "ESDF: max_cells must be between 1 and 2^32 - 1");
}

Eigen::Vector3i EsdfGrid::cell_of(const Eigen::Vector3d& point) const {
  return (point / resolution).array().floor().cast<int>();
}

std::ptrdiff_t EsdfGrid::index(const Eigen::Vector3i& cell) const {
  const Eigen::Vector3i c = cell - first_cell;
  if ((c.array() < 0).any() || (c.array() >= dims.array()).any()) return -1;
  return (std::ptrdiff_t(c.z()) * dims.y() + c.y()) * dims.x() + c.x();
}

float EsdfGrid::distance(const Eigen::Vector3d& point) const {
  const std::ptrdiff_t i = index(cell_of(point));
  return i < 0 ? static_cast<float>(max_distance) : distances[static_cast<std::size_t>(i)];
}

EsdfVolume::EsdfVolume(const compute::Context& context, const TsdfVolumeParams& tsdf,
                       const EsdfVolumeParams& params)
    : context_(&context),
      tsdf_(tsdf),
      params_(params),
      scratch_(std::make_unique<detail::EsdfScratch>(context)) {
  tsdf.validate();
  params.validate();
  cell_voxels_ =
      params.cell_voxels > 0 ? params.cell_voxels : automatic_cell_voxels(tsdf.voxel_size);
  resolution_ = cell_voxels_ * tsdf.voxel_size;
  reach_ = static_cast<int>(std::ceil(params.max_distance / resolution_ - 1e-9));
}

EsdfVolume::~EsdfVolume() = default;
EsdfVolume::EsdfVolume(EsdfVolume&&) noexcept = default;
EsdfVolume& EsdfVolume::operator=(EsdfVolume&&) noexcept = default;

void EsdfVolume::clear() {
  first_ = dims_ = Eigen::Vector3i::Zero();
  marks_ = {};
  distances_ = {};
  generation_ = 0;
  integrations_ = 0;
  empty_ = true;
}

EsdfUpdate EsdfVolume::update(const TsdfVolume& tsdf) {
  require(&tsdf.context() == context_, "ESDF: the TSDF lives on another context");
  require(
      tsdf.params().voxel_size == tsdf_.voxel_size && tsdf.params().truncation == tsdf_.truncation,
      "ESDF: the TSDF has another voxel size or truncation than the ESDF was made for");
  EsdfUpdate out;
  // Integration counts only go back when the block set is replaced, which changes the generation.
  const bool restart = tsdf.generation() != generation_;
  if (restart && !empty_) {
    clear();
    out.restarted = true;
  }
  const std::vector<TsdfBlockRef> blocks = tsdf.blocks_touched_since(
      restart ? std::nullopt : std::optional<std::uint32_t>(integrations_));
  out.changed_blocks = blocks.size();
  if (!blocks.empty()) {
    const int side = kTsdfBlockSide / cell_voxels_;
    Eigen::Vector3i lo = blocks.front().coords, hi = lo;
    for (const TsdfBlockRef& b : blocks) lo = lo.cwiseMin(b.coords), hi = hi.cwiseMax(b.coords);
    lo *= side;
    hi = (hi + Eigen::Vector3i::Ones()) * side;  // exclusive
    // Beyond reach_ + 1 cells of every block, no distance is below max_distance.
    const Eigen::Vector3i margin = Eigen::Vector3i::Constant(reach_ + 1);
    if (empty_ || (lo - margin - first_).minCoeff() < 0 ||
        (first_ + dims_ - (hi + margin)).minCoeff() < 0) {
      grow_to(lo - margin, hi + margin);
      out.grew = true;
    }
    mark(tsdf, blocks);
    const Box outer = around(lo, hi, 2 * reach_);
    transform(outer, around(lo, hi, reach_));
    out.cells_recomputed = volume_of(outer.dims);
  }
  // Only now: an update that threw is done again by the next.
  generation_ = tsdf.generation();
  integrations_ = tsdf.integration_count();
  out.grid_cells = volume_of(dims_);
  return out;
}

// The box of cells [lo - margin, hi + margin) in the grid's cells, cut to the grid.
EsdfVolume::Box EsdfVolume::around(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                                   int margin) const {
  const Eigen::Vector3i m = Eigen::Vector3i::Constant(margin);
  const Eigen::Vector3i first = (lo - m - first_).cwiseMax(Eigen::Vector3i::Zero());
  const Eigen::Vector3i end = (hi + m - first_).cwiseMin(dims_);
  return {first, end - first};
}

// The grid grows to hold [lo, hi) (by at least growth_m per side that grows), keeping its cells.
void EsdfVolume::grow_to(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  Eigen::Vector3i new_lo = lo, new_hi = hi;
  if (!empty_) {
    const int growth = static_cast<int>(std::ceil(params_.growth_m / resolution_ - 1e-9));
    const Eigen::Vector3i end = first_ + dims_;
    for (int a = 0; a < 3; ++a) {
      new_lo[a] = lo[a] < first_[a] ? std::min(lo[a], first_[a] - growth) : first_[a];
      new_hi[a] = hi[a] > end[a] ? std::max(hi[a], end[a] + growth) : end[a];
    }
  }
  const Eigen::Vector3i dims = new_hi - new_lo;
  const double cells = double(dims.x()) * dims.y() * dims.z();
  require(cells <= double(params_.max_cells), "ESDF: a grid of " + cells_text(dims) +
                                                  " exceeds max_cells (" +
                                                  std::to_string(params_.max_cells) + ")");
  // The host's copies of the old and the new grid.
  require_fits_in_memory(cells * kGridBytesPerCell * 2, "ESDF grid of " + cells_text(dims));
  const std::size_t n = volume_of(dims);
  std::vector<std::uint32_t> marks(n, 0);
  std::vector<float> distances(n, static_cast<float>(params_.max_distance));
  if (!empty_) {
    const std::vector<std::uint32_t> old_marks = marks_.to_vector();
    const std::vector<float> old_distances = distances_.to_vector();
    const Eigen::Vector3i offset = first_ - new_lo;
    for (int z = 0; z < dims_.z(); ++z) {
      for (int y = 0; y < dims_.y(); ++y) {
        const std::size_t from = (std::size_t(z) * dims_.y() + y) * dims_.x();
        const std::size_t to =
            (std::size_t(z + offset.z()) * dims.y() + y + offset.y()) * dims.x() + offset.x();
        std::copy_n(old_marks.begin() + from, dims_.x(), marks.begin() + to);
        std::copy_n(old_distances.begin() + from, dims_.x(), distances.begin() + to);
      }
    }
  }
  marks_ = compute::Buffer<std::uint32_t>::from_host(*context_, marks);
  distances_ = compute::Buffer<float>::from_host(*context_, distances);
  first_ = new_lo;
  dims_ = dims;
  empty_ = false;
}

kernels::Esdf3Params EsdfVolume::kernel_params() const {
  kernels::Esdf3Params p{};
  p.cell_voxels = narrow(cell_voxels_);
  p.near = static_cast<float>(tsdf_.voxel_size / tsdf_.truncation);
  p.min_weight = params_.min_weight;
  p.first_x = first_.x(), p.first_y = first_.y(), p.first_z = first_.z();
  p.dims_x = narrow(dims_.x()), p.dims_y = narrow(dims_.y()), p.dims_z = narrow(dims_.z());
  p.resolution = static_cast<float>(resolution_);
  p.max_distance = static_cast<float>(params_.max_distance);
  return p;
}

void EsdfVolume::mark(const TsdfVolume& tsdf, const std::vector<TsdfBlockRef>& blocks) {
  std::vector<std::uint32_t> pool(blocks.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) pool[i] = blocks[i].pool_index;
  if (blocks_.size() < pool.size())
    blocks_ = compute::Buffer<std::uint32_t>(*context_, pool.size());
  blocks_.upload(pool);
  const int side = kTsdfBlockSide / cell_voxels_;
  kernels::Esdf3Params p = kernel_params();
  p.count = narrow(blocks.size() * std::size_t(side * side * side));
  compute::dispatch(*context_, kMarkKernel,
                    {blocks_, tsdf.device_block_keys(), tsdf.device_voxels(), marks_}, p,
                    {compute::groups_for(p.count, KG_ESDF_LOCAL_X), 1});
}

// The exact transform over the outer box, written in the inner box.
void EsdfVolume::transform(const Box& outer, const Box& inner) {
  const std::size_t n = volume_of(outer.dims);
  if (n == 0 || volume_of(inner.dims) == 0) return;
  require_fits_in_memory(double(n) * detail::kEsdfScratchBytesPerCell,
                         "ESDF update over " + cells_text(outer.dims));
  detail::EsdfScratch& scratch = *scratch_;
  scratch.reserve(n);
  kernels::Esdf3Params p = kernel_params();
  p.count = narrow(n);
  p.box_x = narrow(outer.first.x()), p.box_y = narrow(outer.first.y());
  p.box_z = narrow(outer.first.z());
  p.box_dims_x = narrow(outer.dims.x()), p.box_dims_y = narrow(outer.dims.y());
  p.box_dims_z = narrow(outer.dims.z());
  compute::dispatch(*context_, kSeedKernel, {marks_, scratch.a}, p,
                    {compute::groups_for(n, KG_ESDF_LOCAL_X), 1});
  const std::size_t x = outer.dims.x(), y = outer.dims.y(), z = outer.dims.z();
  detail::esdf_envelope({y * z, x, x, y * z, 0, 1}, scratch.a, scratch.b, scratch);
  detail::esdf_envelope({x * z, y, 1, x, x * y, x}, scratch.b, scratch.a, scratch);
  detail::esdf_envelope({x * y, z, 1, x * y, 0, x * y}, scratch.a, scratch.b, scratch);
  p.outer_x = p.box_x, p.outer_y = p.box_y, p.outer_z = p.box_z;
  p.outer_dims_x = p.box_dims_x, p.outer_dims_y = p.box_dims_y;
  p.box_x = narrow(inner.first.x()), p.box_y = narrow(inner.first.y());
  p.box_z = narrow(inner.first.z());
  p.box_dims_x = narrow(inner.dims.x()), p.box_dims_y = narrow(inner.dims.y());
  p.box_dims_z = narrow(inner.dims.z());
  p.count = narrow(volume_of(inner.dims));
  compute::dispatch(*context_, kWriteKernel, {scratch.b, distances_}, p,
                    {compute::groups_for(p.count, KG_ESDF_LOCAL_X), 1});
}

EsdfGrid EsdfVolume::download() const {
  EsdfGrid out;
  out.resolution = resolution_;
  out.max_distance = params_.max_distance;
  out.first_cell = first_;
  out.dims = dims_;
  if (empty_) return out;
  out.distances = distances_.to_vector();
  const std::vector<std::uint32_t> marks = marks_.to_vector();
  out.occupied.assign(marks.begin(), marks.end());
  return out;
}

}  // namespace kartograf::mapping
