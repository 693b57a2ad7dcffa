#pragma once
// A truncated signed distance field (TSDF) with colour, fused frame by frame on the compute
// context's device (CPU, Vulkan or OpenCL; the rules are kernels/tsdf/tsdf.h), as KinectFusion
// and its successors (voxel hashing: Niessner et al. 2013) keep a 3-D map.
//
// Space is cut into blocks of 8^3 voxels of voxel_size; only blocks near an observed surface
// exist (a hash table from block coordinates to a pool of max_blocks blocks). Integrating a depth
// frame at a pose (camera to world):
//   - every valid pixel's ray allocates the blocks it crosses within +-truncation of its depth;
//   - every voxel of those blocks in front of the camera is projected into the depth image, and
//     where the measured depth d is at most `truncation` in front of it (d - z >= -truncation,
//     z the voxel centre's depth) the value min(1, (d - z) / truncation) joins the voxel's running
//     mean with weight 1, or less for far views with fusion_weight_depth (the weight stops
//     growing at max_weight, so the field can follow change);
//     the pixel's colour joins the colour's mean the same way.
// Ray casting marches each pixel's ray through the field (steps bounded by the field's value) to
// the first change from + to -, placed by linear interpolation of the trilinear field.
//
// The field lives on the device from frame to frame; only the status counters (20 bytes) come back
// per frame. A full pool or table is an Error that names the budget; the frame that hit it may be
// partly fused (the blocks that fitted).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/geometry/backproject.hpp"

namespace kartograf::mapping {

inline constexpr int kTsdfBlockSide = 8;
inline constexpr std::size_t kTsdfBlockVoxels = 512;

struct TsdfVolumeParams {
  double voxel_size = 0.01;  // metres
  // Metres either side of the surface that the field describes; at most one block's side
  // (8 voxels) and at least one voxel. 4 voxels by default.
  double truncation = 0.04;
  double max_weight = 64;
  // Metres; 0: every observation joins a voxel's mean with weight 1. Otherwise an observation
  // of a voxel at depth z beyond it weighs (fusion_weight_depth / z)^4: the inverse variance of
  // a structured-light sensor's depth noise, which grows as z^2. Far, noisy views then cannot
  // drag a surface that near views have measured (the frame-to-model tracker's model uses 1.5 m).
  // A mesh's or band's min_weight then counts near-view equivalents: a wall seen once from 3 m
  // weighs 1/16.
  double fusion_weight_depth = 0;
  // The pool: 12 bytes a voxel, 6 KiB a block; 16384 blocks (96 MiB) fit every device's largest
  // buffer (Vulkan guarantees 128 MiB) and hold about 170 m^2 of surface at 1 cm voxels.
  std::size_t max_blocks = 1 << 14;
  // Pixels between the rays that allocate blocks; 0: automatic, the most that keeps the rays at
  // most two voxels apart at the depth range's far end (at most 4; 640x480 at 4 m: 2 at 1 cm
  // voxels, 4 from 2 cm).
  int touch_step = 0;

  // Throws Error naming the field that is out of range.
  void validate() const;
};

struct TsdfVoxel {
  float tsdf = 1;           // signed distance / truncation, in [-1, 1]; + in front of the surface
  float weight = 0;         // 0: never observed
  std::uint32_t color = 0;  // mean colour, 0xBBGGRR
};

// A host copy of the field: the blocks in increasing key order (z, then y, then x), each with its
// 512 voxels (x fastest, then y, then z).
struct TsdfBlocks {
  double voxel_size = 0;
  double truncation = 0;
  std::vector<Eigen::Vector3i> coords;  // block coordinates: voxels 8 b .. 8 b + 7
  std::vector<TsdfVoxel> voxels;        // kTsdfBlockVoxels per block

  std::size_t size() const { return coords.size(); }
  // The block with these coordinates, or -1.
  std::ptrdiff_t find(const Eigen::Vector3i& block) const;
  // The voxel (integral voxel coordinates), or nullptr where no block holds it.
  const TsdfVoxel* voxel(const Eigen::Vector3i& v) const;
};

// A block of the pool: its index there and its coordinates.
struct TsdfBlockRef {
  std::uint32_t pool_index = 0;
  Eigen::Vector3i coords = Eigen::Vector3i::Zero();
};

// What one integration did.
struct TsdfIntegration {
  std::size_t active_blocks = 0;  // blocks the frame touched
  std::size_t total_blocks = 0;   // blocks in the volume after it
};

// A depth frame and its colours (packed 0xBBGGRR) on a context's device, in images and buffers
// kept from frame to frame: uploading the next frame of the same size allocates nothing.
class FrameUpload {
 public:
  explicit FrameUpload(const compute::Context& context) : context_(&context) {}

  // color may be empty (no colour); else it must have the depth's size (Error otherwise).
  void upload(const DepthImage& depth, const RgbImage& color);

  const compute::DeviceImage<std::uint16_t>& depth() const { return depth_; }
  const compute::Buffer<std::uint32_t>* colors() const { return has_colors_ ? &colors_ : nullptr; }

 private:
  const compute::Context* context_;
  compute::DeviceImage<std::uint16_t> depth_;
  compute::Buffer<std::uint32_t> colors_;
  std::vector<std::uint32_t> packed_;  // host staging of the colours
  bool has_colors_ = false;
};

class TsdfVolume {
 public:
  TsdfVolume(const compute::Context& context, const TsdfVolumeParams& params);

  // Fuses a depth frame (and its colour, 0xBBGGRR per pixel, registered to the depth; null: no
  // colour) seen from camera_to_world. Throws Error on a size mismatch, a pose that is not a
  // finite rigid motion, or a full pool/table (naming max_blocks).
  TsdfIntegration integrate(const compute::DeviceImage<std::uint16_t>& depth,
                            const compute::Buffer<std::uint32_t>* colors,
                            const PinholeIntrinsics& camera, const geometry::DepthRange& range,
                            const Eigen::Isometry3d& camera_to_world);
  // The same from host images (colour may be empty).
  TsdfIntegration integrate(const DepthImage& depth, const RgbImage& color,
                            const PinholeIntrinsics& camera, const geometry::DepthRange& range,
                            const Eigen::Isometry3d& camera_to_world);

  // The surface each pixel sees from camera_to_world between range.min_metres and max_metres:
  // points in the camera's frame (invalid where none), and with `colors` each point's colour.
  void raycast(const PinholeIntrinsics& camera, const geometry::DepthRange& range,
               const Eigen::Isometry3d& camera_to_world, compute::DeviceImage<Point4f>& points,
               compute::Buffer<std::uint32_t>* colors = nullptr) const;
  PointImage raycast(const PinholeIntrinsics& camera, const geometry::DepthRange& range,
                     const Eigen::Isometry3d& camera_to_world) const;

  // The most blocks the device's largest buffer holds in one pool (max_blocks may not exceed it).
  static std::size_t largest_pool(const compute::Context& context);

  // Forgets every block: the volume as made, its buffers kept.
  void clear();
  // The volume holds exactly these blocks (a download(), or part of one, of a volume with the
  // same voxel size and truncation): what eviction keeps. last_touched (empty, or one per block,
  // as last_touched() gives them): when each was last touched, kept for the next eviction.
  // Throws Error on other voxels, more blocks than max_blocks, a block twice, or a count of
  // last_touched that is neither 0 nor the blocks'.
  void assign(const TsdfBlocks& blocks, std::span<const std::uint32_t> last_touched = {});
  // Per block, in download()'s order: the number of the last integration that touched it
  // (counted from the volume's making or clear(); higher is more recent).
  std::vector<std::uint32_t> last_touched() const;

  // The blocks integrations after the first `integration` ones touched (by their numbers, as
  // last_touched() gives them), in pool order: what changed since a pass over the field that saw
  // that many integrations. nullopt: every block.
  std::vector<TsdfBlockRef> blocks_touched_since(std::optional<std::uint32_t> integration) const;
  // Integrations so far (counted as last_touched()'s numbers).
  std::uint32_t integration_count() const { return stamp_; }
  // A number no other volume or earlier block set had: it changes when the block set is replaced
  // (clear(), assign()), and then passes that follow changes by integration count
  // (blocks_touched_since) must start again.
  std::uint64_t generation() const { return generation_; }

  std::size_t block_count() const { return block_count_; }
  const TsdfVolumeParams& params() const { return params_; }
  // The pool on the device, for other passes over the field (the first block_count() blocks are
  // in use; block_keys holds each one's key).
  const compute::Context& context() const { return *context_; }
  const compute::Buffer<std::uint64_t>& device_block_keys() const { return block_keys_; }
  const compute::Buffer<TsdfVoxel>& device_voxels() const { return voxels_; }
  // The block table (kernels/voxel_hash: 2^table_log2() slots of keys, each slot's pool index).
  const compute::Buffer<std::uint64_t>& device_table_keys() const { return keys_; }
  const compute::Buffer<std::uint32_t>& device_table_blocks() const { return slot_blocks_; }
  unsigned table_log2() const { return capacity_log2_; }
  TsdfBlocks download() const;

 private:
  std::vector<std::uint32_t> stamps_by_pool_block() const;  // last integration per pool block

  const compute::Context* context_;
  TsdfVolumeParams params_;
  unsigned capacity_log2_ = 0;
  std::uint32_t stamp_ = 0;
  std::uint64_t generation_ = 0;
  std::size_t block_count_ = 0;
  compute::Buffer<std::uint64_t> keys_;         // the table: block keys
  compute::Buffer<std::uint32_t> slot_blocks_;  // the table: pool index per slot
  compute::Buffer<std::uint32_t> stamps_;       // the table: last frame that touched the slot
  compute::Buffer<std::uint64_t> block_keys_;   // the pool: key per block
  compute::Buffer<std::uint32_t> active_;       // this frame's blocks
  compute::Buffer<std::uint32_t> status_;
  compute::Buffer<TsdfVoxel> voxels_;  // the pool: 512 per block
  FrameUpload upload_;                 // the host overload's frames
  // The ray cast's tiles: where blocks can lie on their rays (refilled by each ray cast).
  mutable compute::Buffer<std::uint32_t> ranges_;
};

}  // namespace kartograf::mapping
