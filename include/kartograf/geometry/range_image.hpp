#pragma once
// A spherical range image of an unorganized cloud (a fused map, a merged scan) as seen from a
// viewpoint: the organized layout that the M2 labelling (semantic/classify.hpp) needs, made from
// data that has none.
//
// Layout as the laser scans (synth/laser_scan.hpp, the DLUT scans): sensor frame x forward,
// y left, z up; column c looks at azimuth pi - (c + 0.5) * step (column 0 behind, turning right
// through ahead), all 360 degrees; row 0 is the highest elevation. Each pixel keeps the nearest
// point whose ray falls in it, in the sensor frame.
//
// A map's points are samples of surfaces, not opaque beams: seen from a viewpoint the map was
// not made from, a far wall shows through the gaps between the samples of a near one. Each point
// therefore occludes a disc of `surface_radius` around itself (its angular radius at its range,
// at most max_splat_pixels): a pixel whose nearest point lies more than a range-relative margin
// behind an occluding disc stays empty.
#include <cstdint>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kartograf/core/image.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::geometry {

struct RangeImageParams {
  // Per column and per row. Coarser than the map's sampling seen from the viewpoint, or most
  // pixels stay empty: 1 degree is 5 cm at 3 m.
  double angular_step_deg = 1.0;
  double min_elevation_deg = -70.0, max_elevation_deg = 80.0;
  double min_range = 0.1, max_range = 30.0;  // metres; points outside are left out
  double surface_radius = 0.03;              // metres: the disc a point occludes; 0: no occlusion
  int max_splat_pixels = 6;
  double occlusion_margin = 0.05;  // relative: behind a disc by more than this x its range

  void validate() const;  // throws Error naming the first bad field
};

struct RangeImage {
  Eigen::Isometry3d sensor_to_world = Eigen::Isometry3d::Identity();
  PointImage points;          // sensor frame; invalid_point() where no point is seen
  Image<std::int32_t> index;  // the input point of each pixel, -1 where none
};

// The cloud's points (world frame; non-finite ones skipped) seen from `sensor_to_world`. Throws
// Error on bad parameters or a non-finite pose.
RangeImage make_range_image(std::span<const Eigen::Vector3f> points,
                            const Eigen::Isometry3d& sensor_to_world,
                            const RangeImageParams& params = {});

}  // namespace kartograf::geometry
