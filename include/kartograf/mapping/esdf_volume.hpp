#pragma once
// The 3-D Euclidean distance field (ESDF) of a TSDF (tsdf_volume.hpp), for planning: metres from
// each cell of a dense grid to the nearest surface, at most max_distance, kept on the TSDF's
// device and updated incrementally (the rules: kernels/esdf/esdf3.h).
//
// A cell is cell_voxels^3 TSDF voxels (so cells nest in the TSDF's 8^3 blocks); it is occupied
// where one of its voxels is surface: observed (weight >= min_weight) and within one voxel in front
// of a surface or behind it (the rule of the 2-D band, tsdf_slice.hpp). A cell's distance is that
// between its centre and the nearest occupied cell's centre (0 in occupied cells), capped at
// max_distance; max_distance too where nothing is occupied within it, also outside the grid.
//
// update() takes what the TSDF's integrations changed since the last update (the blocks they
// touched), re-marks those blocks' cells and recomputes the exact transform over a box around
// them: the box reaches 2 x max_distance beyond the blocks, and the distances written, those up to
// max_distance beyond, are all a change can move. The result is the whole grid's transform (the
// tests check it cell for cell), at the cost of the region around the change, not of the map.
// The grid covers the blocks with max_distance of margin on every side and grows (by at least
// growth_m per side, keeping what it holds) when blocks appear beyond it. When the TSDF's block
// set is replaced (clear(), assign(): the mapper's and the tracker's eviction) the field starts
// again from the blocks left: it always describes the live TSDF.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"

namespace kartograf::kernels {
struct Esdf3Params;
}

namespace kartograf::mapping {

namespace detail {
struct EsdfScratch;
}

struct EsdfVolumeParams {
  // TSDF voxels per cell side: 1, 2, 4 or 8; 0: the fewest that make a cell at least 5 cm (1 cm
  // voxels: 8 cm cells; 2 cm: 8 cm; 5 cm: 5 cm).
  int cell_voxels = 0;
  double max_distance = 1.0;  // metres; the cost of an update grows with its cube
  float min_weight = 3;       // as the band's (tsdf_slice.hpp)
  double growth_m = 2.0;      // the least the grid grows by per side
  // The grid's budget: 8 bytes a cell, plus 36 per cell of an update's box.
  std::size_t max_cells = std::size_t(1) << 27;

  void validate() const;  // Error naming the field
};

// A host copy: the grid's cells, x fastest, then y, then z.
struct EsdfGrid {
  double resolution = 0;                // metres per cell
  double max_distance = 0;              // metres
  Eigen::Vector3i first_cell{0, 0, 0};  // cell (i, j, k) spans [i, i + 1) x resolution, ...
  Eigen::Vector3i dims{0, 0, 0};
  std::vector<float> distances;
  std::vector<std::uint8_t> occupied;

  std::size_t size() const { return distances.size(); }
  // The cell holding a world point (floor of point / resolution).
  Eigen::Vector3i cell_of(const Eigen::Vector3d& point) const;
  // The distance of the cell holding the point: max_distance outside the grid.
  float distance(const Eigen::Vector3d& point) const;
  // The index of a cell in the grid's vectors, or -1 outside.
  std::ptrdiff_t index(const Eigen::Vector3i& cell) const;
};

// What one update did.
struct EsdfUpdate {
  std::size_t changed_blocks = 0;
  std::size_t cells_recomputed = 0;  // the box's
  std::size_t grid_cells = 0;
  bool restarted = false;  // the TSDF's block set was replaced: the field started again
  bool grew = false;
};

class EsdfVolume {
 public:
  // For TSDFs of these parameters, on the context's device. Throws Error on bad parameters.
  EsdfVolume(const compute::Context& context, const TsdfVolumeParams& tsdf,
             const EsdfVolumeParams& params = {});
  ~EsdfVolume();
  EsdfVolume(EsdfVolume&&) noexcept;
  EsdfVolume& operator=(EsdfVolume&&) noexcept;

  // Brings the field up to date with the TSDF (on the same context, with the parameters given
  // when this was made). Throws Error on another voxel size or context, or a grid that would
  // exceed max_cells or the host's memory (naming the cells).
  EsdfUpdate update(const TsdfVolume& tsdf);
  EsdfGrid download() const;
  // Forgets everything: the next update starts from the TSDF's blocks.
  void clear();

  double resolution() const { return resolution_; }
  int cell_voxels() const { return cell_voxels_; }
  const EsdfVolumeParams& params() const { return params_; }
  Eigen::Vector3i first_cell() const { return first_; }
  Eigen::Vector3i dims() const { return dims_; }
  // On the device: the grid's marks (1: occupied) and distances, x fastest.
  const compute::Buffer<std::uint32_t>& device_marks() const { return marks_; }
  const compute::Buffer<float>& device_distances() const { return distances_; }

 private:
  struct Box {
    Eigen::Vector3i first, dims;  // in the grid's cells
  };
  void grow_to(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi);
  void mark(const TsdfVolume& tsdf, const std::vector<TsdfBlockRef>& blocks);
  void transform(const Box& outer, const Box& inner);
  Box around(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi, int margin) const;
  kernels::Esdf3Params kernel_params() const;  // the grid's part

  const compute::Context* context_;
  TsdfVolumeParams tsdf_;
  EsdfVolumeParams params_;
  int cell_voxels_ = 1;
  double resolution_ = 0;
  int reach_ = 0;  // cells a change can move distances by: ceil(max_distance / resolution)
  Eigen::Vector3i first_{0, 0, 0}, dims_{0, 0, 0};
  compute::Buffer<std::uint32_t> marks_;
  compute::Buffer<float> distances_;
  compute::Buffer<std::uint32_t> blocks_;  // the update's blocks, by pool index
  std::uint64_t generation_ = 0;           // the TSDF's, when last updated
  std::uint32_t integrations_ = 0;         // the TSDF's integrations seen
  bool empty_ = true;                      // no grid yet
  std::unique_ptr<detail::EsdfScratch> scratch_;
};

}  // namespace kartograf::mapping
