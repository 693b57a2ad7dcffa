#include "kartograf/mapping/tsdf_volume.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/memory_budget.hpp"
#include "kartograf/core/pose.hpp"
#include "kartograf/core/sort_order.hpp"
#include "kernels/tsdf/tsdf.h"

namespace kartograf::mapping {

namespace {

static_assert(sizeof(TsdfVoxel) == sizeof(kernels::TsdfVoxel) && sizeof(TsdfVoxel) == 12);
static_assert(kTsdfBlockSide == KG_TSDF_BLOCK_SIDE && kTsdfBlockVoxels == KG_TSDF_BLOCK_VOXELS);

constexpr compute::KernelSpec kTouchKernel{"tsdf_touch", KG_TSDF_LOCAL_2D, KG_TSDF_LOCAL_2D};
constexpr compute::KernelSpec kAssignKernel{"tsdf_assign", KG_TSDF_LOCAL_X};
constexpr compute::KernelSpec kIntegrateKernel{"tsdf_integrate", KG_TSDF_LOCAL_X};
constexpr compute::KernelSpec kRaycastKernel{"tsdf_raycast", KG_TSDF_LOCAL_2D, KG_TSDF_LOCAL_2D};
constexpr compute::KernelSpec kRangeKernel{"tsdf_range", KG_TSDF_LOCAL_X};
// 2^23 blocks of 512 voxels keep every voxel index below 2^32.
constexpr std::size_t kMaxBlocks = std::size_t{1} << 23;

// The parameter block for a camera at a pose; the passes fill in count, step and has_color.
kernels::TsdfParams frame_params(const TsdfVolumeParams& volume, const PinholeIntrinsics& camera,
                                 const geometry::DepthRange& range,
                                 const Eigen::Isometry3d& camera_to_world) {
  const geometry::DepthUnits units = geometry::valid_depth_units(range);
  kernels::TsdfParams p{};
  p.width = static_cast<std::uint32_t>(camera.width);
  p.height = static_cast<std::uint32_t>(camera.height);
  p.min_units = units.min;
  p.max_units = units.max;
  p.metres_per_unit = static_cast<float>(1.0 / range.units_per_metre);
  p.fx = static_cast<float>(camera.fx);
  p.fy = static_cast<float>(camera.fy);
  p.cx = static_cast<float>(camera.cx);
  p.cy = static_cast<float>(camera.cy);
  p.voxel_size = static_cast<float>(volume.voxel_size);
  p.truncation = static_cast<float>(volume.truncation);
  p.max_weight = static_cast<float>(volume.max_weight);
  p.inverse_voxel = static_cast<float>(1.0 / volume.voxel_size);
  p.weight_depth = static_cast<float>(volume.fusion_weight_depth);
  const Eigen::Matrix3f r = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f t = camera_to_world.translation().cast<float>();
  p.r00 = r(0, 0), p.r01 = r(0, 1), p.r02 = r(0, 2);
  p.r10 = r(1, 0), p.r11 = r(1, 1), p.r12 = r(1, 2);
  p.r20 = r(2, 0), p.r21 = r(2, 1), p.r22 = r(2, 2);
  p.tx = t.x(), p.ty = t.y(), p.tz = t.z();
  return p;
}

void require_rigid(const Eigen::Isometry3d& pose, const char* what) {
  require(is_rigid(pose, 1e-4),
          std::string("TSDF volume: the ") + what + " pose is not a finite rigid motion");
}

// touch_step, or where it is 0 the most pixels between touching rays that keeps them at most two
// voxels apart at the far end of the depth range (at most 4): a block every ray missed would be a
// sliver of a block's corner. 640x480 at 4 m: 2 at 1 cm voxels, 4 from 2 cm. On the synthetic
// survey, seeds 1 and 2, this left accuracy and completeness as they were with 1
// (docs/volumetric.md).
int touch_step_for(const TsdfVolumeParams& params, const PinholeIntrinsics& camera,
                   const geometry::DepthRange& range) {
  if (params.touch_step > 0) return params.touch_step;
  const double pixels = 2 * params.voxel_size * std::min(camera.fx, camera.fy) / range.max_metres;
  return std::clamp(static_cast<int>(std::floor(pixels)), 1, 4);
}

// Fills `ranges` with the tiles' depth ranges for a ray cast with parameters p over the first
// `blocks` blocks of the pool (kernels/tsdf/tsdf.h).
void cast_ranges(const compute::Context& context, const compute::Buffer<std::uint64_t>& block_keys,
                 std::size_t blocks, kernels::TsdfParams p,
                 compute::Buffer<std::uint32_t>& ranges) {
  const std::size_t values = 2 * std::size_t{kernels::tsdf_tile_count(p)};
  if (ranges.size() != values) ranges = compute::Buffer<std::uint32_t>(context, values);
  ranges.fill_zero();
  if (blocks == 0) return;
  p.count = static_cast<std::uint32_t>(blocks);
  compute::dispatch(context, kRangeKernel, {block_keys, ranges}, p,
                    {compute::groups_for(blocks, KG_TSDF_LOCAL_X), 1});
}

std::string blocks_text(std::size_t blocks) {
  return std::to_string(blocks) + " blocks (" +
         memory_size_text(static_cast<double>(blocks) * kTsdfBlockVoxels * sizeof(TsdfVoxel)) + ")";
}

}  // namespace

void TsdfVolumeParams::validate() const {
  require(std::isfinite(voxel_size) && voxel_size >= 1e-4 && voxel_size <= 10,
          "TSDF volume: voxel_size must be in [0.0001, 10] m, got " + std::to_string(voxel_size));
  require(std::isfinite(truncation) && truncation >= voxel_size &&
              truncation <= voxel_size * kTsdfBlockSide,
          "TSDF volume: truncation must be between one voxel and one block (8 voxels), got " +
              std::to_string(truncation) + " m for voxels of " + std::to_string(voxel_size) + " m");
  require(std::isfinite(max_weight) && max_weight >= 1,
          "TSDF volume: max_weight must be >= 1, got " + std::to_string(max_weight));
  require(std::isfinite(fusion_weight_depth) && fusion_weight_depth >= 0,
          "TSDF volume: fusion_weight_depth must be >= 0 m (0: every observation weighs 1), got " +
              std::to_string(fusion_weight_depth));
  require(max_blocks >= 1 && max_blocks <= kMaxBlocks,
          "TSDF volume: max_blocks must be in [1, 2^23], got " + std::to_string(max_blocks));
  require(touch_step >= 0, "TSDF volume: touch_step must be >= 0 (0: automatic)");
}

std::ptrdiff_t TsdfBlocks::find(const Eigen::Vector3i& block) const {
  // Sorted by key: z, then y, then x.
  const auto before = [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::tie(a.z(), a.y(), a.x()) < std::tie(b.z(), b.y(), b.x());
  };
  const auto it = std::lower_bound(coords.begin(), coords.end(), block, before);
  return it != coords.end() && *it == block ? it - coords.begin() : -1;
}

const TsdfVoxel* TsdfBlocks::voxel(const Eigen::Vector3i& v) const {
  const Eigen::Vector3i block(v.x() >> 3, v.y() >> 3, v.z() >> 3);
  const std::ptrdiff_t b = find(block);
  if (b < 0) return nullptr;
  const Eigen::Vector3i local = v - block * kTsdfBlockSide;
  return &voxels[static_cast<std::size_t>(b) * kTsdfBlockVoxels + local.x() + 8 * local.y() +
                 64 * local.z()];
}

std::size_t TsdfVolume::largest_pool(const compute::Context& context) {
  const std::uint64_t largest = context.device_info().limits.max_buffer_bytes;
  if (largest == 0) return std::numeric_limits<std::size_t>::max();  // the device states none
  return static_cast<std::size_t>(largest / (kTsdfBlockVoxels * sizeof(TsdfVoxel)));
}

TsdfVolume::TsdfVolume(const compute::Context& context, const TsdfVolumeParams& params)
    : context_(&context), params_(params), upload_(context) {
  params_.validate();
  capacity_log2_ = static_cast<unsigned>(std::bit_width(params_.max_blocks * 2 - 1));
  const std::size_t slots = std::size_t{1} << capacity_log2_;
  const double bytes =
      static_cast<double>(params_.max_blocks) * (kTsdfBlockVoxels * sizeof(TsdfVoxel) + 12) +
      static_cast<double>(slots) * 16;
  require_fits_in_memory(bytes, "TSDF volume of " + blocks_text(params_.max_blocks));
  require(params_.max_blocks <= largest_pool(context),
          "TSDF volume: a pool of " + blocks_text(params_.max_blocks) +
              " is larger than the device's largest buffer (" +
              memory_size_text(static_cast<double>(context.device_info().limits.max_buffer_bytes)) +
              "); lower max_blocks");
  keys_ = compute::Buffer<std::uint64_t>(context, slots);
  slot_blocks_ = compute::Buffer<std::uint32_t>(context, slots);
  stamps_ = compute::Buffer<std::uint32_t>(context, slots);
  block_keys_ = compute::Buffer<std::uint64_t>(context, params_.max_blocks);
  active_ = compute::Buffer<std::uint32_t>(context, params_.max_blocks);
  status_ = compute::Buffer<std::uint32_t>(context, KG_TSDF_STATUS_VALUES);
  voxels_ = compute::Buffer<TsdfVoxel>(context, params_.max_blocks * kTsdfBlockVoxels);
  clear();
}

void TsdfVolume::clear() {
  keys_.fill_zero();
  slot_blocks_.upload(std::vector<std::uint32_t>(keys_.size(), KG_TSDF_NO_BLOCK));
  stamps_.fill_zero();
  status_.fill_zero();
  voxels_.fill_zero();
  block_count_ = 0;
  stamp_ = 0;
  // Unique across volumes: a pass that followed another volume (or this one before) starts again.
  static std::atomic<std::uint64_t> generations{0};
  generation_ = ++generations;
}

void TsdfVolume::assign(const TsdfBlocks& blocks, std::span<const std::uint32_t> last_touched) {
  require(blocks.voxel_size == params_.voxel_size && blocks.truncation == params_.truncation,
          "TSDF volume: the blocks assigned have another voxel size or truncation");
  require(blocks.voxels.size() == blocks.size() * kTsdfBlockVoxels,
          "TSDF volume: the blocks assigned hold the wrong number of voxels");
  require(blocks.size() <= params_.max_blocks, "TSDF volume: " + blocks_text(blocks.size()) +
                                                   " assigned to a pool of " +
                                                   blocks_text(params_.max_blocks));
  require(last_touched.empty() || last_touched.size() == blocks.size(),
          "TSDF volume: last_touched must be empty or one per block assigned");
  // The table as the device's insertions would make it, built here with the same rule, before
  // anything is forgotten: a refused set leaves the volume as it was.
  const std::size_t n = blocks.size();
  std::vector<std::uint32_t> stamps(keys_.size(), 0);
  std::vector<std::uint64_t> table(keys_.size(), KG_EMPTY_VOXEL_KEY);
  std::vector<std::uint32_t> slot_blocks(keys_.size(), KG_TSDF_NO_BLOCK);
  std::vector<std::uint64_t> block_keys(n);
  for (std::size_t b = 0; b < n; ++b) {
    const Eigen::Vector3i& c = blocks.coords[b];
    block_keys[b] = kernels::tsdf_block_key(c.x(), c.y(), c.z());
    const int slot = kernels::voxel_insert_key(table.data(), block_keys[b], capacity_log2_);
    require(slot >= 0 && slot_blocks[static_cast<std::size_t>(slot)] == KG_TSDF_NO_BLOCK,
            "TSDF volume: a block assigned twice");
    slot_blocks[static_cast<std::size_t>(slot)] = static_cast<std::uint32_t>(b);
    if (!last_touched.empty()) stamps[static_cast<std::size_t>(slot)] = last_touched[b];
  }
  const std::uint32_t stamp = stamp_;
  clear();
  if (n == 0) return;
  // Integrations go on counting from where they were, above every stamp kept.
  stamp_ = last_touched.empty()
               ? 0
               : std::max(stamp, *std::max_element(last_touched.begin(), last_touched.end()));
  keys_.upload(table);
  stamps_.upload(stamps);
  slot_blocks_.upload(slot_blocks);
  block_keys_.upload(block_keys);
  voxels_.upload(blocks.voxels);
  std::vector<std::uint32_t> status(KG_TSDF_STATUS_VALUES, 0);
  status[KG_TSDF_STATUS_BLOCKS] = static_cast<std::uint32_t>(n);
  status_.upload(status);
  block_count_ = n;
}

TsdfIntegration TsdfVolume::integrate(const compute::DeviceImage<std::uint16_t>& depth,
                                      const compute::Buffer<std::uint32_t>* colors,
                                      const PinholeIntrinsics& camera,
                                      const geometry::DepthRange& range,
                                      const Eigen::Isometry3d& camera_to_world) {
  camera.validate("TSDF integration");
  require(depth.width() == camera.width && depth.height() == camera.height,
          "TSDF integration: the depth image is " + std::to_string(depth.width()) + "x" +
              std::to_string(depth.height()) + " but the camera is " +
              std::to_string(camera.width) + "x" + std::to_string(camera.height));
  require(!colors || colors->size() == depth.size(),
          "TSDF integration: the colour image's size differs from the depth image's");
  require_rigid(camera_to_world, "camera");
  kernels::TsdfParams p = frame_params(params_, camera, range, camera_to_world);
  stamp_ = stamp_ == 0xffffffffu ? 1 : stamp_ + 1;
  p.stamp = stamp_;
  p.capacity_log2 = capacity_log2_;
  p.block_capacity = static_cast<std::uint32_t>(params_.max_blocks);
  p.step = static_cast<std::uint32_t>(touch_step_for(params_, camera, range));
  p.has_color = colors ? 1u : 0u;
  const std::uint32_t step = p.step;
  compute::dispatch(*context_, kTouchKernel, {depth.buffer(), keys_, stamps_, status_}, p,
                    {compute::groups_for((camera.width + step - 1) / step, KG_TSDF_LOCAL_2D),
                     compute::groups_for((camera.height + step - 1) / step, KG_TSDF_LOCAL_2D)});
  p.count = static_cast<std::uint32_t>(keys_.size());
  compute::dispatch(*context_, kAssignKernel,
                    {keys_, slot_blocks_, block_keys_, stamps_, active_, status_}, p,
                    {compute::groups_for(keys_.size(), KG_TSDF_LOCAL_X), 1});
  std::array<std::uint32_t, KG_TSDF_STATUS_VALUES> status{};
  status_.download(status);
  require(status[KG_TSDF_STATUS_OUT_OF_RANGE] == 0,
          "TSDF integration: " + std::to_string(status[KG_TSDF_STATUS_OUT_OF_RANGE]) +
              " surface points lie beyond 2^20 blocks from the origin");
  require(status[KG_TSDF_STATUS_OUT_OF_BLOCKS] == 0 && status[KG_TSDF_STATUS_TABLE_FULL] == 0,
          "TSDF integration: the volume is full: the frame needs more than its " +
              blocks_text(params_.max_blocks) + "; raise max_blocks or the voxel size");
  block_count_ = status[KG_TSDF_STATUS_BLOCKS];
  const std::size_t active = status[KG_TSDF_STATUS_ACTIVE];
  status[KG_TSDF_STATUS_ACTIVE] = 0;  // the next frame counts its own
  status_.upload(status);
  if (active > 0) {
    p.count = static_cast<std::uint32_t>(active * kTsdfBlockVoxels);
    compute::dispatch(*context_, kIntegrateKernel,
                      {depth.buffer(), colors ? compute::BufferArg(*colors) : compute::BufferArg(),
                       active_, block_keys_, voxels_},
                      p, {compute::groups_for(p.count, KG_TSDF_LOCAL_X), 1});
  }
  return {active, block_count_};
}

void FrameUpload::upload(const DepthImage& depth, const RgbImage& color) {
  require(color.empty() || (color.width() == depth.width() && color.height() == depth.height()),
          "TSDF integration: the colour image's size differs from the depth image's");
  if (depth_.width() != depth.width() || depth_.height() != depth.height()) {
    depth_ = compute::DeviceImage<std::uint16_t>(*context_, depth.width(), depth.height());
  }
  depth_.upload(depth);
  has_colors_ = !color.empty();
  if (!has_colors_) return;
  packed_.resize(color.pixels().size());
  std::transform(color.pixels().begin(), color.pixels().end(), packed_.begin(), pack_rgb);
  colors_.refer_or_upload(*context_, packed_);
}

TsdfIntegration TsdfVolume::integrate(const DepthImage& depth, const RgbImage& color,
                                      const PinholeIntrinsics& camera,
                                      const geometry::DepthRange& range,
                                      const Eigen::Isometry3d& camera_to_world) {
  upload_.upload(depth, color);
  return integrate(upload_.depth(), upload_.colors(), camera, range, camera_to_world);
}

void TsdfVolume::raycast(const PinholeIntrinsics& camera, const geometry::DepthRange& range,
                         const Eigen::Isometry3d& camera_to_world,
                         compute::DeviceImage<Point4f>& points,
                         compute::Buffer<std::uint32_t>* colors) const {
  camera.validate("TSDF ray casting");
  require_rigid(camera_to_world, "ray casting");
  if (points.width() != camera.width || points.height() != camera.height) {
    points = compute::DeviceImage<Point4f>(*context_, camera.width, camera.height);
  }
  if (colors && colors->size() != points.size()) {
    *colors = compute::Buffer<std::uint32_t>(*context_, points.size());
  }
  kernels::TsdfParams p = frame_params(params_, camera, range, camera_to_world);
  p.capacity_log2 = capacity_log2_;
  p.block_capacity = static_cast<std::uint32_t>(params_.max_blocks);
  p.has_color = colors ? 1u : 0u;
  // Enough steps of one voxel each to cross the whole range.
  const double span = range.max_metres - range.min_metres;
  p.step = static_cast<std::uint32_t>(std::min(1e6, std::ceil(span / params_.voxel_size) + 2));
  cast_ranges(*context_, block_keys_, std::min(block_count_, params_.max_blocks), p, ranges_);
  compute::dispatch(*context_, kRaycastKernel,
                    {keys_, slot_blocks_, voxels_, points.buffer(),
                     colors ? compute::BufferArg(*colors) : compute::BufferArg(), ranges_},
                    p,
                    {compute::groups_for(camera.width, KG_TSDF_LOCAL_2D),
                     compute::groups_for(camera.height, KG_TSDF_LOCAL_2D)});
}

PointImage TsdfVolume::raycast(const PinholeIntrinsics& camera, const geometry::DepthRange& range,
                               const Eigen::Isometry3d& camera_to_world) const {
  compute::DeviceImage<Point4f> points;
  raycast(camera, range, camera_to_world, points);
  return points.to_image();
}

std::vector<std::uint32_t> TsdfVolume::stamps_by_pool_block() const {
  const std::size_t n = std::min(block_count_, params_.max_blocks);
  std::vector<std::uint32_t> by_block(n, 0);
  const std::vector<std::uint32_t> slot_blocks = slot_blocks_.to_vector();
  const std::vector<std::uint32_t> stamps = stamps_.to_vector();
  for (std::size_t slot = 0; slot < slot_blocks.size(); ++slot) {
    if (slot_blocks[slot] < n) by_block[slot_blocks[slot]] = stamps[slot];
  }
  return by_block;
}

std::vector<std::uint32_t> TsdfVolume::last_touched() const {
  const std::size_t n = std::min(block_count_, params_.max_blocks);
  if (n == 0) return {};
  const std::vector<std::uint32_t> by_block = stamps_by_pool_block();
  std::vector<std::uint64_t> block_keys(n);
  block_keys_.download(block_keys);
  const std::vector<std::size_t> order =
      ascending_order(std::span<const std::uint64_t>(block_keys));  // download()'s
  std::vector<std::uint32_t> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = by_block[order[i]];
  return out;
}

std::vector<TsdfBlockRef> TsdfVolume::blocks_touched_since(
    std::optional<std::uint32_t> integration) const {
  const std::size_t n = std::min(block_count_, params_.max_blocks);
  std::vector<TsdfBlockRef> out;
  if (n == 0) return out;
  const std::vector<std::uint32_t> by_block = stamps_by_pool_block();
  std::vector<std::uint64_t> block_keys(n);
  block_keys_.download(block_keys);
  for (std::size_t b = 0; b < n; ++b) {
    if (integration && by_block[b] <= *integration) continue;
    const std::uint64_t key = block_keys[b];
    out.push_back({static_cast<std::uint32_t>(b),
                   Eigen::Vector3i(kernels::tsdf_key_axis(key, 0), kernels::tsdf_key_axis(key, 21),
                                   kernels::tsdf_key_axis(key, 42))});
  }
  return out;
}

TsdfBlocks TsdfVolume::download() const {
  TsdfBlocks out;
  out.voxel_size = params_.voxel_size;
  out.truncation = params_.truncation;
  const std::size_t n = std::min(block_count_, params_.max_blocks);
  std::vector<std::uint64_t> keys(n);
  std::vector<TsdfVoxel> voxels(n * kTsdfBlockVoxels);
  if (n > 0) {
    block_keys_.download(keys);
    voxels_.download(voxels);
  }
  const std::vector<std::size_t> order = ascending_order(std::span<const std::uint64_t>(keys));
  out.coords.reserve(n);
  out.voxels.reserve(n * kTsdfBlockVoxels);
  for (const std::size_t b : order) {
    out.coords.emplace_back(kernels::tsdf_key_axis(keys[b], 0), kernels::tsdf_key_axis(keys[b], 21),
                            kernels::tsdf_key_axis(keys[b], 42));
    const auto first = voxels.begin() + static_cast<std::ptrdiff_t>(b * kTsdfBlockVoxels);
    out.voxels.insert(out.voxels.end(), first, first + kTsdfBlockVoxels);
  }
  return out;
}

}  // namespace kartograf::mapping
