#include "kartograf/registration/voxel_hash_correspondences.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <tuple>
#include <unordered_map>

#include "geometry/voxel_key.hpp"
#include "kartograf/compute/kernel.hpp"
#include "kernels/voxel_hash_nearest/voxel_hash_nearest.h"
#include "registration/nearest_neighbor.hpp"

namespace kartograf::registration {

namespace {

constexpr compute::KernelSpec kNearestKernel{"voxel_hash_nearest", KG_VOXEL_HASH_NEAREST_LOCAL_X};
constexpr double kCellMargin = 0x1p-20;  // cell edge = max_distance / (1 - 2^-20)
static_assert(KG_NEAREST_NO_MATCH == kNoMatch && KG_NEAREST_NOT_SELECTED == kNotSelected);
static_assert(KG_NEAREST_FRAME_VALUES == std::tuple_size_v<decltype(detail::NearestQuery::frame)>);

template <class T>
void upload_resized(const compute::Context& context, compute::Buffer<T>& buffer,
                    std::span<const T> values) {
  if (buffer.size() != values.size()) buffer = compute::Buffer<T>(context, values.size());
  buffer.upload(values);
}

// The grid on the host: cells in the order of their first point, the points sorted by cell
// (stable), and the table of cells (key -> first, count).
struct HostGrid {
  std::vector<std::uint64_t> keys;     // per slot: cell key, 0 = empty
  std::vector<std::uint32_t> ranges;   // per slot: first, count (into the sorted points)
  std::vector<Point4f> points;         // target points sorted by cell
  std::vector<std::uint32_t> indices;  // their indices in the target
  std::size_t cell_count = 0;
  unsigned capacity_log2 = 0;
};

// The cell of every valid point (0xffffffff for invalid ones), the cells' keys in the order of
// their first point, and how many points each has.
struct CellsOfPoints {
  std::vector<std::uint32_t> point_cells;
  std::vector<std::uint64_t> keys;
  std::vector<std::uint32_t> counts;
};

CellsOfPoints cells_of_points(std::span<const Point4f> points, double cell_inverse,
                              double cell_size) {
  CellsOfPoints cells;
  cells.point_cells.assign(points.size(), 0xffffffffu);
  std::unordered_map<std::uint64_t, std::uint32_t> cell_of_key;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_valid(points[i])) continue;
    Eigen::Vector3d cell;
    require(geometry::detail::voxel_of(points[i].head<3>().cast<double>() * cell_inverse, cell),
            "voxel-hash correspondences: target point " + std::to_string(i) +
                " lies beyond 2^20 cells of " + std::to_string(cell_size) +
                " m from the origin (or has NaN/Inf coordinates)");
    const auto [entry, inserted] = cell_of_key.try_emplace(
        geometry::detail::voxel_key(cell), static_cast<std::uint32_t>(cells.keys.size()));
    if (inserted) {
      cells.keys.push_back(entry->first);
      cells.counts.push_back(0);
    }
    cells.point_cells[i] = entry->second;
    ++cells.counts[entry->second];
  }
  return cells;
}

HostGrid build_grid(std::span<const Point4f> points, double cell_inverse, double cell_size) {
  const CellsOfPoints cells = cells_of_points(points, cell_inverse, cell_size);
  std::vector<std::uint32_t> starts(cells.counts.size());
  std::uint32_t running = 0;
  for (std::size_t c = 0; c < starts.size(); ++c) {
    starts[c] = running;
    running += cells.counts[c];
  }
  HostGrid grid;
  std::vector<std::uint32_t> cursor = starts;
  grid.points.assign(running, Point4f::Zero());
  grid.indices.assign(running, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (cells.point_cells[i] == 0xffffffffu) continue;
    const std::uint32_t m = cursor[cells.point_cells[i]]++;
    grid.points[m] = points[i];
    grid.indices[m] = static_cast<std::uint32_t>(i);
  }
  grid.cell_count = cells.keys.size();
  grid.capacity_log2 = geometry::detail::hash_capacity_log2(grid.cell_count);
  grid.keys.assign(std::size_t{1} << grid.capacity_log2, geometry::detail::kEmptyVoxelKey);
  grid.ranges.assign(std::size_t{2} << grid.capacity_log2, 0);
  for (std::size_t c = 0; c < grid.cell_count; ++c) {
    std::uint32_t slot = kernels::voxel_slot(cells.keys[c], grid.capacity_log2);
    while (grid.keys[slot] != geometry::detail::kEmptyVoxelKey) {
      slot = kernels::voxel_next_slot(slot, grid.capacity_log2);
    }
    grid.keys[slot] = cells.keys[c];
    grid.ranges[2 * slot] = starts[c];
    grid.ranges[2 * slot + 1] = cells.counts[c];
  }
  return grid;
}

}  // namespace

VoxelHashCorrespondences::VoxelHashCorrespondences(const compute::Context& context)
    : context_(&context), frame_(context, KG_NEAREST_FRAME_VALUES) {}

void VoxelHashCorrespondences::prepare(const CloudView&, int) {
  stale_ = true;
}

void VoxelHashCorrespondences::build(const CloudView& target, double max_distance) {
  cell_inverse_ = (1.0 - kCellMargin) / max_distance;
  cell_size_ = 1.0 / cell_inverse_;
  const HostGrid grid =
      build_grid(compute::read_on_host(*target.points), cell_inverse_, cell_size_);
  cell_count_ = grid.cell_count;
  capacity_log2_ = grid.capacity_log2;
  upload_resized<std::uint64_t>(*context_, keys_, grid.keys);
  upload_resized<std::uint32_t>(*context_, ranges_, grid.ranges);
  upload_resized<Point4f>(*context_, points_, grid.points);
  upload_resized<std::uint32_t>(*context_, indices_, grid.indices);
  built_for_ = target.points;
  built_distance_ = max_distance;
  stale_ = false;
}

void VoxelHashCorrespondences::find(const CloudView& source, const CloudView& target,
                                    const Eigen::Isometry3d& source_to_target,
                                    const AssociationParams& params, CorrespondenceBuffers& out) {
  detail::NearestQuery query = detail::make_query(source_to_target, params);
  detail::validate(source, target, params, query.use_normals, "voxel-hash correspondences");
  require(source_to_target.matrix().allFinite(),
          "voxel-hash correspondences: the pose has NaN/Inf entries");
  if (stale_ || built_for_ != target.points || built_distance_ != params.max_distance) {
    build(target, params.max_distance);
  }
  query.frame[KG_NEAREST_FRAME_CELL_INVERSE] = cell_inverse_;
  if (out.target_index.size() != source.size()) {
    out.target_index = compute::Buffer<std::int32_t>(*context_, source.size());
  }
  if (source.size() == 0) return;
  const auto width = source.camera ? static_cast<std::uint32_t>(source.camera->width) : 0u;
  frame_.upload(query.frame);
  const auto optional = [&](const compute::Buffer<Point4f>* buffer) {
    return query.use_normals ? compute::BufferArg(*buffer) : compute::BufferArg();
  };
  compute::dispatch(
      *context_, kNearestKernel,
      {*source.points, optional(source.normals), optional(target.normals), keys_, ranges_, points_,
       indices_, frame_, out.target_index},
      kernels::VoxelHashNearestParams{static_cast<std::uint32_t>(source.size()), width,
                                      static_cast<std::uint32_t>(params.subsample), capacity_log2_,
                                      query.use_normals ? 1u : 0u},
      {compute::groups_for(source.size(), kNearestKernel.local_x), 1});
}

}  // namespace kartograf::registration
