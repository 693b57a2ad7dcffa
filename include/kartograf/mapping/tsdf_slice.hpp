#pragma once
// The robot's 2-D maps from a TSDF (tsdf_volume.hpp): the occupancy grid of its height band and
// the Euclidean signed distance field (ESDF) of that grid, for planning.
//
// In a frame whose z axis points up (world_to_level; the world itself by default), each observed
// voxel (weight >= min_weight) whose centre lies within one voxel in front of a surface or behind
// it (tsdf x truncation < voxel_size) is surface. A grid cell is
//   occupied  where surface voxels lie in the band floor_z + [band_min, band_max];
//   free      where, with no surface in the band, the floor's surface was seen (within
//             floor_tolerance of floor_z);
//   unknown   otherwise (the field keeps only a band around surfaces, so open space with no
//             floor in view is not known to be free).
// The grid covers the footprint of the field's blocks (the centres of their voxels), origin at its
// lower-left corner.
#include <Eigen/Geometry>

#include "kartograf/core/image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/mapping/tsdf_volume.hpp"

namespace kartograf::mapping {

struct TsdfSliceParams {
  Eigen::Isometry3d world_to_level = Eigen::Isometry3d::Identity();
  double floor_z = 0;  // metres, in the level frame
  double floor_tolerance = 0.04;
  double band_min = 0.05;  // metres above the floor
  double band_max = 1.5;
  double resolution = 0.05;  // metres per cell
  // Voxels fused from fewer frames are left out: a single view's flying pixels (depth mixed
  // across an object's outline) leave surfaces in mid-air that later views do not all carve.
  float min_weight = 3;

  void validate() const;  // Error naming the field
};

OccupancyGrid tsdf_occupancy(const TsdfBlocks& blocks, const TsdfSliceParams& params);
// The same on the field's device (kernels/tsdf/tsdf_band.h: each voxel marks its cell): only the
// block keys and the grid cross to the host. Equal to the host's on a downloaded copy but where a
// voxel centre lies within rounding of a cell's edge (float here, double there).
OccupancyGrid tsdf_occupancy(const TsdfVolume& volume, const TsdfSliceParams& params);

// Metres from each cell centre to the nearest occupied cell's centre for free and unknown cells,
// minus the distance to the nearest non-occupied cell inside occupied ones; +infinity everywhere
// when nothing is occupied.
Image<float> occupancy_esdf(const OccupancyGrid& grid);
// The same on a context's device (kernels/esdf: the exact transform in integers, so equal to the
// host's but for the device's square root).
Image<float> occupancy_esdf(const compute::Context& context, const OccupancyGrid& grid);

// The band's grid and its ESDF, both made on the field's device: only the block keys and the two
// results cross to the host.
struct TsdfBandMaps {
  OccupancyGrid occupancy;
  Image<float> esdf;
};
TsdfBandMaps tsdf_band_maps(const TsdfVolume& volume, const TsdfSliceParams& params);

}  // namespace kartograf::mapping
