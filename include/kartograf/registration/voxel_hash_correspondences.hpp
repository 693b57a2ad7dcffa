#pragma once
// Nearest-neighbour correspondences for unorganized clouds on the device: the target's valid points
// are bucketed into a voxel-hash grid whose cell edge is at least max_distance, so every point
// within max_distance of a query lies in the 27 cells around it; each source point searches those
// cells. Exact within the radius: the same partner as a brute-force search (and the k-d tree),
// with the rules of kdtree_correspondences.hpp, on every backend.
//
// The grid is built on the host once per target (and max_distance): cell = floor(q * s) per axis
// with s = (1 - 2^-20) / max_distance (the margin keeps rounding from hiding a neighbour two cells
// away), cells in an open-addressing table (key -> first, count) over the points sorted by cell,
// then uploaded (sorted points and their indices, 20 bytes per point; keys and ranges, 16 bytes
// per slot, >= 2 slots per cell). Cells are keyed as in voxel_downsample.hpp: a target point beyond
// 2^20 cells of the origin is an Error. A query visits its own cell, then those of the other 26
// whose nearest face is not farther than the best candidate so far (which cannot change the
// answer), and computes the distances to their points.
#include <cstdint>
#include <vector>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/registration/correspondence_finder.hpp"

namespace kartograf::registration {

class VoxelHashCorrespondences : public CorrespondenceFinder {
 public:
  explicit VoxelHashCorrespondences(const compute::Context& context);

  // Marks the grid for rebuilding from target at the next find().
  void prepare(const CloudView& target, int level) override;
  // Builds the grid when prepare() was called, the target buffer changed or max_distance changed.
  void find(const CloudView& source, const CloudView& target,
            const Eigen::Isometry3d& source_to_target, const AssociationParams& params,
            CorrespondenceBuffers& out) override;

  std::size_t cell_count() const { return cell_count_; }
  double cell_size() const { return cell_size_; }  // of the current grid

 private:
  void build(const CloudView& target, double max_distance);

  const compute::Context* context_;
  bool stale_ = true;
  const compute::Buffer<Point4f>* built_for_ = nullptr;
  double built_distance_ = 0;
  double cell_inverse_ = 0;
  double cell_size_ = 0;
  std::size_t cell_count_ = 0;
  unsigned capacity_log2_ = 0;
  // The grid.
  compute::Buffer<std::uint64_t> keys_;     // per slot: cell key, 0 = empty
  compute::Buffer<std::uint32_t> ranges_;   // per slot: first, count (into the sorted points)
  compute::Buffer<Point4f> points_;         // target points sorted by cell
  compute::Buffer<std::uint32_t> indices_;  // their indices in the target
  compute::Buffer<double> frame_;
};

}  // namespace kartograf::registration
