#pragma once
// Judging an ICP result before using it, and weighting it in a pose graph. Odometry and loop
// closure accept a registration only when enough of the source found partners (fitness), the
// partners fit (RMSE), every direction of motion was constrained (degeneracy) and the result lies
// near the motion that was expected (the initial guess); a rejected registration is reported with
// the reason, never chained silently.
#include <cstdint>
#include <string_view>

#include <Eigen/Geometry>

#include "kartograf/core/se3.hpp"
#include "kartograf/registration/icp_result.hpp"

namespace kartograf::registration {

struct RegistrationLimits {
  std::uint64_t min_inliers = 200;
  double min_fitness = 0.3;  // inliers / considered source points
  double max_rmse = 0.02;    // metres, the metric's inlier RMSE
  bool reject_degenerate = true;
  // The result may differ from the expected motion by at most this much (T_expected^-1 T).
  double max_correction_m = 0.3;
  double max_correction_deg = 20;
};

// In the order they are checked: the first failed check names the verdict.
enum class RegistrationVerdict {
  accepted,
  too_few_pairs,  // fewer than min_inliers inliers
  low_fitness,
  high_rmse,
  degenerate,
  implausible,  // too far from the expected motion
  unconfirmed,  // a second, independent measurement (e.g. local features) disagrees
};
std::string_view to_string(RegistrationVerdict verdict);

// What a caller reports about one registration (per-frame statistics, loop closures).
struct RegistrationReport {
  RegistrationVerdict verdict = RegistrationVerdict::too_few_pairs;
  double fitness = 0;
  double inlier_rmse = 0;
  std::uint64_t inliers = 0;
  int iterations = 0;
  bool converged = false;
  bool degenerate = true;
  double eigenvalue_ratio = 0;  // DegeneracyReport::eigenvalue_ratio
  double correction_m = 0;      // |translation of T_expected^-1 T|
  double correction_deg = 0;    // rotation angle of T_expected^-1 T
  bool accepted() const { return verdict == RegistrationVerdict::accepted; }
};

// The correction T_expected^-1 T of a registration's answer: translation (metres), rotation
// (degrees); and whether it is within RegistrationLimits' max_correction_m and _deg.
struct Correction {
  double metres = 0, degrees = 0;
};
Correction correction_of(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& motion);
bool within_limits(const Correction& correction, const RegistrationLimits& limits);

// Degeneracy as ICP's sums see it (IcpResult::degeneracy), or as given (geometric_information.hpp).
RegistrationReport judge_registration(const IcpResult& result, const Eigen::Isometry3d& expected,
                                      const RegistrationLimits& limits);
RegistrationReport judge_registration(const IcpResult& result, const Eigen::Isometry3d& expected,
                                      const RegistrationLimits& limits,
                                      const DegeneracyReport& degeneracy);

// How much a registration is trusted in a pose graph. A sum of J^T J over N pairs (ICP's, or
// geometric_information.hpp's) would claim millimetre-per-thousand-points certainty: neighbouring
// pairs share their errors (depth bias, calibration, the surface model), so a registration is
// worth about `effective_pairs` independent pairs, each with the measured residual noise:
//   Omega = effective_pairs x (J^T J per pair) / sigma^2,  sigma = max(inlier_rmse, min_sigma).
struct InformationModel {
  double effective_pairs = 500;
  double min_sigma = 0.002;  // metres
};
se3::Matrix6d edge_information(const se3::Matrix6d& information_per_pair, double inlier_rmse,
                               const InformationModel& model);

// A weak information for a motion that was not measured (a motion-model fallback): independent
// rotation and translation standard deviations.
se3::Matrix6d prior_information(double sigma_rotation_rad, double sigma_translation_m);

// Adds an independent error (standard deviations per axis) to an edge: covariances add, so
// Omega' = (Omega^-1 + diag(sigma_rotation^2 x3, sigma_translation^2 x3))^-1. For errors that grow
// with the motion itself, such as depth-calibration bias in wide-baseline registrations. Omega may
// be singular: the directions it leaves free stay free.
se3::Matrix6d with_added_error(const se3::Matrix6d& information, double sigma_rotation_rad,
                               double sigma_translation_m);

}  // namespace kartograf::registration
