#include "kartograf/registration/registration_check.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace kartograf::registration {

std::string_view to_string(RegistrationVerdict verdict) {
  switch (verdict) {
    case RegistrationVerdict::accepted:
      return "accepted";
    case RegistrationVerdict::too_few_pairs:
      return "too_few_pairs";
    case RegistrationVerdict::low_fitness:
      return "low_fitness";
    case RegistrationVerdict::high_rmse:
      return "high_rmse";
    case RegistrationVerdict::degenerate:
      return "degenerate";
    case RegistrationVerdict::implausible:
      return "implausible";
    case RegistrationVerdict::unconfirmed:
      return "unconfirmed";
  }
  return "unknown";
}

Correction correction_of(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& motion) {
  const Eigen::Isometry3d correction = expected.inverse() * motion;
  return {correction.translation().norm(),
          se3::rotation_angle(correction) * 180.0 / std::numbers::pi};
}

bool within_limits(const Correction& correction, const RegistrationLimits& limits) {
  return correction.metres <= limits.max_correction_m &&
         correction.degrees <= limits.max_correction_deg;
}

RegistrationReport judge_registration(const IcpResult& result, const Eigen::Isometry3d& expected,
                                      const RegistrationLimits& limits) {
  return judge_registration(result, expected, limits, result.degeneracy);
}

RegistrationReport judge_registration(const IcpResult& result, const Eigen::Isometry3d& expected,
                                      const RegistrationLimits& limits,
                                      const DegeneracyReport& degeneracy) {
  RegistrationReport report;
  report.fitness = result.fitness;
  report.inlier_rmse = result.inlier_rmse;
  report.inliers = result.inlier_count;
  report.iterations = result.iterations;
  report.converged = result.converged;
  report.degenerate = degeneracy.degenerate;
  report.eigenvalue_ratio = degeneracy.eigenvalue_ratio;
  const Correction correction = correction_of(expected, result.source_to_target);
  report.correction_m = correction.metres;
  report.correction_deg = correction.degrees;

  const bool finite = result.source_to_target.matrix().allFinite();
  if (!finite || result.inlier_count < limits.min_inliers) {
    report.verdict = RegistrationVerdict::too_few_pairs;
  } else if (!(result.fitness >= limits.min_fitness)) {
    report.verdict = RegistrationVerdict::low_fitness;
  } else if (!(result.inlier_rmse <= limits.max_rmse)) {
    report.verdict = RegistrationVerdict::high_rmse;
  } else if (limits.reject_degenerate && degeneracy.degenerate) {
    report.verdict = RegistrationVerdict::degenerate;
  } else if (!within_limits(correction, limits)) {
    report.verdict = RegistrationVerdict::implausible;
  } else {
    report.verdict = RegistrationVerdict::accepted;
  }
  return report;
}

se3::Matrix6d edge_information(const se3::Matrix6d& information_per_pair, double inlier_rmse,
                               const InformationModel& model) {
  const double sigma = std::max(inlier_rmse, model.min_sigma);
  const se3::Matrix6d information =
      information_per_pair * (model.effective_pairs / (sigma * sigma));
  // Exactly symmetric: the pose graph's LDLT and chi^2 assume it.
  return 0.5 * (information + information.transpose());
}

se3::Matrix6d prior_information(double sigma_rotation_rad, double sigma_translation_m) {
  se3::Vector6d diagonal;
  const double r = 1.0 / (sigma_rotation_rad * sigma_rotation_rad);
  const double t = 1.0 / (sigma_translation_m * sigma_translation_m);
  diagonal << r, r, r, t, t, t;
  return diagonal.asDiagonal();
}

se3::Matrix6d with_added_error(const se3::Matrix6d& information, double sigma_rotation_rad,
                               double sigma_translation_m) {
  // (Omega^-1 + S)^-1 = (I + Omega S)^-1 Omega: no inverse of Omega, so an information that
  // leaves directions free (zero eigenvalues) keeps them free.
  se3::Vector6d added;
  added << Eigen::Vector3d::Constant(sigma_rotation_rad * sigma_rotation_rad),
      Eigen::Vector3d::Constant(sigma_translation_m * sigma_translation_m);
  const se3::Matrix6d mixed = se3::Matrix6d::Identity() + information * added.asDiagonal();
  const se3::Matrix6d result = mixed.partialPivLu().solve(information);
  return 0.5 * (result + result.transpose());
}

}  // namespace kartograf::registration
