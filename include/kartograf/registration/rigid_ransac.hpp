#pragma once
// The rigid motion behind 3-D point pairs of which many are wrong (feature matches): RANSAC on
// minimal samples of 3 pairs, each solved in closed form (Umeyama, no scale), then refitted on
// the consensus. Eigen only, so that it serves any front end (features/orb_front_end.hpp).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

namespace kartograf::registration {

struct RigidRansacParams {
  // A pair is an inlier when |T source - target| <= base + slope * source depth (the source
  // point's z, metres): Kinect-type depth noise grows with z^2, so a fixed radius either rejects
  // good far pairs or accepts bad near ones.
  double inlier_base_m = 0.02;
  double inlier_slope = 0.01;    // metres per metre of depth
  std::size_t min_inliers = 15;  // fewer agreeing pairs: no answer
  std::size_t max_iterations = 2000;
  // Stop once the chance that every sample so far held an outlier is below this.
  double miss_probability = 1e-3;
  // A sample whose 3 points span a triangle thinner than this (its smallest height, metres) is
  // skipped: nearly collinear points leave the rotation about their line free.
  double min_sample_spread_m = 0.02;
  std::uint64_t seed = 1;  // the same seed and pairs give the same answer
};

struct RigidRansacResult {
  Eigen::Isometry3d source_to_target = Eigen::Isometry3d::Identity();
  std::size_t inliers = 0;
  double inlier_rmse_m = 0;       // of the final inliers under the final motion
  std::vector<bool> inlier_mask;  // per pair
  std::size_t iterations = 0;     // samples drawn (degenerate ones included)
};

// The motion T with T source[i] ~ target[i] for the most pairs. Nothing when fewer than
// params.min_inliers pairs agree (or there are fewer than 3 pairs). Throws Error when the two
// lists differ in length or a parameter is out of range.
std::optional<RigidRansacResult> estimate_rigid_ransac(const std::vector<Eigen::Vector3d>& source,
                                                       const std::vector<Eigen::Vector3d>& target,
                                                       const RigidRansacParams& params = {});

}  // namespace kartograf::registration
