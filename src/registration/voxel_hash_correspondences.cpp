#include "kartograf/registration/voxel_hash_correspondences.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "geometry/voxel_key.hpp"
#include "kartograf/compute/kernel.hpp"
#include "registration/nearest_neighbor.hpp"

namespace kartograf::registration {

namespace {

constexpr compute::KernelSpec kNearestKernel{"voxel_hash_nearest", 64};
constexpr double kCellMargin = 0x1p-20;  // cell edge = max_distance / (1 - 2^-20)
constexpr double kGapMargin = 1e-9;      // cells: > the rounding of p * s for |p * s| < 2^21

struct NearestKernelParams {  // layout of shaders/voxel_hash_nearest.comp and the .cl kernel
  std::uint32_t source_count;
  std::uint32_t source_width;
  std::uint32_t subsample;
  std::uint32_t capacity_log2;
  std::uint32_t use_normals;
};

// The kernel's search, for one moved source point, over the host copy of the grid.
struct HostGrid {
  std::span<const std::uint64_t> keys;
  std::span<const std::uint32_t> ranges;
  std::span<const Point4f> points;
  std::span<const std::uint32_t> indices;
  unsigned capacity_log2;
  double cell_inverse;

  std::int32_t nearest(const Eigen::Vector3d& moved, double max_distance_sq,
                       const NormalGate* gate) const {
    const Eigen::Vector3d scaled = moved * cell_inverse;
    const Eigen::Vector3d base(std::floor(scaled.x()), std::floor(scaled.y()),
                               std::floor(scaled.z()));
    const double bound = geometry::detail::kVoxelLimit + 1.0;
    if (!(std::fabs(base.x()) <= bound && std::fabs(base.y()) <= bound &&
          std::fabs(base.z()) <= bound)) {
      return kNoMatch;
    }
    const Eigen::Vector3d fraction = scaled - base;  // the query's place in its cell, [0, 1]
    const double cell_sq = 1.0 / (cell_inverse * cell_inverse);
    const std::uint32_t mask = (std::uint32_t{1} << capacity_log2) - 1;
    detail::Nearest best(max_distance_sq);
    // The query's own cell first; then a cell is skipped when even its nearest face is farther
    // than the best so far (gaps shrunk by 1e-9 cells against rounding, so none is lost).
    constexpr int kOrder[3] = {0, -1, 1};
    for (const int dz : kOrder) {
      for (const int dy : kOrder) {
        for (const int dx : kOrder) {
          const Eigen::Vector3i offset(dx, dy, dz);
          double gap_sq = 0;
          for (int axis = 0; axis < 3; ++axis) {
            if (offset(axis) == 0) continue;
            const double gap = offset(axis) < 0 ? fraction(axis) : 1.0 - fraction(axis);
            gap_sq += std::max(gap - kGapMargin, 0.0) * std::max(gap - kGapMargin, 0.0);
          }
          if (gap_sq * cell_sq > best.distance_sq) continue;
          Eigen::Vector3d cell;
          if (!geometry::detail::voxel_of(base + offset.cast<double>(), cell)) continue;
          const std::uint64_t key = geometry::detail::voxel_key(cell);
          std::uint32_t slot = geometry::detail::voxel_slot(key, capacity_log2);
          while (keys[slot] != key && keys[slot] != geometry::detail::kEmptyVoxelKey)
            slot = (slot + 1) & mask;
          if (keys[slot] == geometry::detail::kEmptyVoxelKey) continue;
          const std::uint32_t first = ranges[2 * slot], end = first + ranges[2 * slot + 1];
          for (std::uint32_t m = first; m < end; ++m) {
            const auto j = static_cast<std::int32_t>(indices[m]);
            const double distance_sq = detail::squared_distance(moved, points[m]);
            if (best.improves(j, distance_sq) && (!gate || gate->accepts(indices[m]))) {
              best.take(j, distance_sq);
            }
          }
        }
      }
    }
    return best.index;
  }
};

template <class T>
void upload_resized(const compute::Context& context, compute::Buffer<T>& buffer,
                    std::vector<T>& values) {
  if (buffer.size() != values.size()) buffer = compute::Buffer<T>(context, values.size());
  buffer.upload(values);
  std::vector<T>().swap(values);  // the device holds the grid now
}

}  // namespace

VoxelHashCorrespondences::VoxelHashCorrespondences(const compute::Context& context)
    : context_(&context) {
  if (!context.is_cpu()) frame_ = compute::Buffer<double>(context, 15);
}

void VoxelHashCorrespondences::prepare(const CloudView&, int) {
  stale_ = true;
}

void VoxelHashCorrespondences::build(const CloudView& target, double max_distance) {
  std::vector<Point4f> downloaded;
  std::span<const Point4f> points;
  if (context_->is_cpu()) {
    points = target.points->host_span();
  } else {
    downloaded = target.points->to_vector();
    points = downloaded;
  }
  cell_inverse_ = (1.0 - kCellMargin) / max_distance;
  cell_size_ = 1.0 / cell_inverse_;

  // Cells in the order of their first point, then the points sorted by cell (stable).
  std::unordered_map<std::uint64_t, std::uint32_t> cell_of_key;
  std::vector<std::uint64_t> cell_keys;
  std::vector<std::uint32_t> cell_starts;
  std::vector<std::uint32_t> point_cells(points.size(), 0xffffffffu);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_valid(points[i])) continue;
    Eigen::Vector3d cell;
    require(geometry::detail::voxel_of(points[i].head<3>().cast<double>() * cell_inverse_, cell),
            "voxel-hash correspondences: target point " + std::to_string(i) +
                " lies beyond 2^20 cells of " + std::to_string(cell_size_) +
                " m from the origin (or has NaN/Inf coordinates)");
    const auto [entry, inserted] = cell_of_key.try_emplace(
        geometry::detail::voxel_key(cell), static_cast<std::uint32_t>(cell_keys.size()));
    if (inserted) {
      cell_keys.push_back(entry->first);
      cell_starts.push_back(0);
    }
    point_cells[i] = entry->second;
    ++cell_starts[entry->second];
  }
  std::uint32_t running = 0;
  for (std::uint32_t& start : cell_starts) {
    const std::uint32_t count = start;
    start = running;
    running += count;
  }
  std::vector<std::uint32_t> cursor = cell_starts;
  host_points_.assign(running, Point4f::Zero());
  host_indices_.assign(running, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (point_cells[i] == 0xffffffffu) continue;
    const std::uint32_t m = cursor[point_cells[i]]++;
    host_points_[m] = points[i];
    host_indices_[m] = static_cast<std::uint32_t>(i);
  }

  cell_count_ = cell_keys.size();
  capacity_log2_ = geometry::detail::hash_capacity_log2(cell_count_);
  const std::uint32_t mask = (std::uint32_t{1} << capacity_log2_) - 1;
  host_keys_.assign(std::size_t{1} << capacity_log2_, geometry::detail::kEmptyVoxelKey);
  host_ranges_.assign(std::size_t{2} << capacity_log2_, 0);
  for (std::size_t c = 0; c < cell_count_; ++c) {
    std::uint32_t slot = geometry::detail::voxel_slot(cell_keys[c], capacity_log2_);
    while (host_keys_[slot] != geometry::detail::kEmptyVoxelKey) slot = (slot + 1) & mask;
    host_keys_[slot] = cell_keys[c];
    host_ranges_[2 * slot] = cell_starts[c];
    host_ranges_[2 * slot + 1] =
        (c + 1 < cell_count_ ? cell_starts[c + 1] : running) - cell_starts[c];
  }
  if (!context_->is_cpu()) {
    upload_resized(*context_, keys_, host_keys_);
    upload_resized(*context_, ranges_, host_ranges_);
    upload_resized(*context_, points_, host_points_);
    upload_resized(*context_, indices_, host_indices_);
  }
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
  query.frame[12] = cell_inverse_;
  if (out.target_index.size() != source.size()) {
    out.target_index = compute::Buffer<std::int32_t>(*context_, source.size());
  }
  if (source.size() == 0) return;
  const auto width = source.camera ? static_cast<std::uint32_t>(source.camera->width) : 0u;
  const auto k = static_cast<std::uint32_t>(params.subsample);

  if (context_->is_cpu()) {
    const HostGrid grid{host_keys_,    host_ranges_,   host_points_,
                        host_indices_, capacity_log2_, cell_inverse_};
    const double max_distance_sq = query.max_distance_sq();
    detail::find_each(query, source.points->host_span(),
                      query.use_normals ? source.normals->host_span() : std::span<const Point4f>(),
                      query.use_normals ? target.normals->host_span() : std::span<const Point4f>(),
                      width, k, out.target_index.host_span(),
                      [&](const Eigen::Vector3d& moved, const NormalGate* gate) {
                        return grid.nearest(moved, max_distance_sq, gate);
                      });
    return;
  }
  frame_.upload(query.frame);
  const auto optional = [&](const compute::Buffer<Point4f>* buffer) {
    return query.use_normals ? compute::BufferArg(*buffer) : compute::BufferArg();
  };
  compute::dispatch(*context_, kNearestKernel,
                    {*source.points, optional(source.normals), optional(target.normals), keys_,
                     ranges_, points_, indices_, frame_, out.target_index},
                    NearestKernelParams{static_cast<std::uint32_t>(source.size()), width, k,
                                        capacity_log2_, query.use_normals ? 1u : 0u},
                    {compute::groups_for(source.size(), kNearestKernel.local_x), 1});
}

}  // namespace kartograf::registration
