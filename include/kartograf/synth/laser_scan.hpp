#pragma once
// An organized 3-D laser scan of the synthetic world, laid out like the DLUT scans
// (../shared/data/dlut_laser_scans): a 2-D scanner sweeping 180 degrees in 0.5 degree steps
// (361 columns), tilted line by line through an elevation range (one image row per line).
//
// Sensor frame: x forward, y left, z up (as the DLUT scans: z vertical). Column c looks at
// azimuth -fov/2 + c * fov / (columns - 1) (column 0 on the right, -y); row 0 is the highest
// elevation. Points are in the sensor frame; sensor_to_world places them in the world.
#include <cstdint>

#include <Eigen/Geometry>

#include "kartograf/core/label_image.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/semantic_class.hpp"
#include "kartograf/synth/ray_caster.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::synth {

struct LidarScanParams {
  int columns = 361;
  double horizontal_fov_deg = 180.0;
  int lines = 201;
  double min_elevation_deg = -40.0;
  double max_elevation_deg = 60.0;
  double range_sigma = 0.01;  // metres, Gaussian range noise (0: exact)
  double min_range = 0.1;
  double max_range = 30.0;
  double grazing_limit_deg = 85.0;  // no return beyond this incidence angle
  double dark_albedo = 0.05;        // no return with probability 1 - albedo / dark_albedo below it
  int threads = 0;                  // 0: all cores

  void validate() const;
};

struct LaserScan {
  Eigen::Isometry3d sensor_to_world = Eigen::Isometry3d::Identity();
  PointImage points;        // sensor frame; invalid_point() where there is no return
  LabelImage plane_id;      // ground truth of each beam (also where the return was dropped)
  SemanticImage semantic;   // ground truth
  Image<float> range_true;  // exact range [m] of each beam, NaN where it hits nothing
};

LaserScan scan_laser(const RayCaster& caster, const Eigen::Isometry3d& sensor_to_world,
                     const LidarScanParams& options, std::uint64_t seed);

// The unit direction of beam (column, row) in the sensor frame.
Eigen::Vector3d laser_beam_direction(const LidarScanParams& options, int column, int row);

// A scanner 0.8 m above the floor at the most open point of the largest room, facing the room's
// longer extent.
Eigen::Isometry3d default_scan_pose(const World& world);

}  // namespace kartograf::synth
