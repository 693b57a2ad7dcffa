// RANSAC for a rigid motion from 3-D point pairs (registration/rigid_ransac.hpp).
#include "kartograf/registration/rigid_ransac.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"
#include "kartograf/core/random.hpp"

namespace kartograf::registration {
namespace {

using Points = std::vector<Eigen::Vector3d>;

void validate(const Points& source, const Points& target, const RigidRansacParams& p) {
  require(source.size() == target.size(), "rigid RANSAC: " + std::to_string(source.size()) +
                                              " source points but " +
                                              std::to_string(target.size()) + " target points");
  require(std::isfinite(p.inlier_base_m) && p.inlier_base_m > 0,
          "rigid RANSAC: inlier_base_m must be positive");
  require(std::isfinite(p.inlier_slope) && p.inlier_slope >= 0,
          "rigid RANSAC: inlier_slope must not be negative");
  require(p.min_inliers >= 3, "rigid RANSAC: min_inliers must be at least 3");
  require(p.max_iterations >= 1, "rigid RANSAC: max_iterations must be at least 1");
  require(p.miss_probability > 0 && p.miss_probability < 1,
          "rigid RANSAC: miss_probability must be in (0, 1)");
  require(p.min_sample_spread_m >= 0, "rigid RANSAC: min_sample_spread_m must not be negative");
}

// Squared inlier radius per pair: base + slope * depth of the source point.
std::vector<double> squared_thresholds(const Points& source, const RigidRansacParams& p) {
  std::vector<double> result(source.size());
  for (std::size_t i = 0; i < source.size(); ++i) {
    const double r = p.inlier_base_m + p.inlier_slope * std::max(0.0, source[i].z());
    result[i] = r * r;
  }
  return result;
}

// The smallest height of the triangle abc: how far the 3 points are from one line.
double smallest_height(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c) {
  const double twice_area = (b - a).cross(c - a).norm();
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  return longest > 0 ? twice_area / longest : 0.0;
}

// Umeyama without scale on the pairs listed in `indices`.
Eigen::Isometry3d fit(const Points& source, const Points& target,
                      const std::vector<std::size_t>& indices) {
  Eigen::Matrix3Xd s(3, indices.size()), t(3, indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) {
    s.col(static_cast<Eigen::Index>(k)) = source[indices[k]];
    t.col(static_cast<Eigen::Index>(k)) = target[indices[k]];
  }
  Eigen::Isometry3d result;
  result.matrix() = Eigen::umeyama(s, t, false);
  return result;
}

std::size_t count_inliers(const Points& source, const Points& target,
                          const std::vector<double>& squared_radius, const Eigen::Isometry3d& t) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < source.size(); ++i)
    if ((t * source[i] - target[i]).squaredNorm() <= squared_radius[i]) ++count;
  return count;
}

std::vector<std::size_t> inlier_indices(const Points& source, const Points& target,
                                        const std::vector<double>& squared_radius,
                                        const Eigen::Isometry3d& t) {
  std::vector<std::size_t> result;
  for (std::size_t i = 0; i < source.size(); ++i)
    if ((t * source[i] - target[i]).squaredNorm() <= squared_radius[i]) result.push_back(i);
  return result;
}

// Samples needed so that, with an inlier ratio `ratio`, every 3-sample so far holding an outlier
// has probability below `miss`.
std::size_t samples_needed(double ratio, double miss, std::size_t cap) {
  const double all_good = ratio * ratio * ratio;
  if (all_good >= 1.0) return 1;
  if (all_good <= 0.0) return cap;
  const double needed = std::ceil(std::log(miss) / std::log1p(-all_good));
  return needed < static_cast<double>(cap) ? static_cast<std::size_t>(needed) : cap;
}

// 3 distinct indices below n (n >= 3).
std::array<std::size_t, 3> draw_sample(Rng& rng, std::size_t n) {
  const int last = static_cast<int>(n) - 1;
  std::array<std::size_t, 3> s{};
  s[0] = static_cast<std::size_t>(rng.uniform_int(0, last));
  do s[1] = static_cast<std::size_t>(rng.uniform_int(0, last));
  while (s[1] == s[0]);
  do s[2] = static_cast<std::size_t>(rng.uniform_int(0, last));
  while (s[2] == s[0] || s[2] == s[1]);
  return s;
}

struct Hypothesis {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  std::size_t inliers = 0;
  std::size_t iterations = 0;
};

// The sample hypothesis with the most inliers, drawn until the adaptive count or the cap.
Hypothesis best_sample(const Points& source, const Points& target,
                       const std::vector<double>& squared_radius, const RigidRansacParams& p) {
  Rng rng(p.seed);
  Hypothesis best;
  std::size_t needed = p.max_iterations;
  while (best.iterations < needed) {
    ++best.iterations;
    const auto s = draw_sample(rng, source.size());
    if (smallest_height(source[s[0]], source[s[1]], source[s[2]]) < p.min_sample_spread_m ||
        smallest_height(target[s[0]], target[s[1]], target[s[2]]) < p.min_sample_spread_m)
      continue;
    const Eigen::Isometry3d motion = fit(source, target, {s[0], s[1], s[2]});
    const std::size_t inliers = count_inliers(source, target, squared_radius, motion);
    if (inliers <= best.inliers) continue;
    best.motion = motion;
    best.inliers = inliers;
    const double ratio = static_cast<double>(inliers) / static_cast<double>(source.size());
    needed = samples_needed(ratio, p.miss_probability, p.max_iterations);
  }
  return best;
}

double rmse(const Points& source, const Points& target, const std::vector<std::size_t>& indices,
            const Eigen::Isometry3d& t) {
  double sum = 0;
  for (const std::size_t i : indices) sum += (t * source[i] - target[i]).squaredNorm();
  return indices.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(indices.size()));
}

}  // namespace

std::optional<RigidRansacResult> estimate_rigid_ransac(const Points& source, const Points& target,
                                                       const RigidRansacParams& params) {
  validate(source, target, params);
  if (source.size() < 3) return std::nullopt;
  const std::vector<double> squared_radius = squared_thresholds(source, params);
  const Hypothesis best = best_sample(source, target, squared_radius, params);
  if (best.inliers < params.min_inliers) return std::nullopt;
  // The sample's motion rests on 3 pairs; the consensus set pins it down, and may then grow.
  const auto consensus = inlier_indices(source, target, squared_radius, best.motion);
  const Eigen::Isometry3d refined = fit(source, target, consensus);
  const auto final_inliers = inlier_indices(source, target, squared_radius, refined);
  if (final_inliers.size() < params.min_inliers) return std::nullopt;

  RigidRansacResult result;
  result.source_to_target = refined;
  result.inliers = final_inliers.size();
  result.inlier_rmse_m = rmse(source, target, final_inliers, refined);
  result.inlier_mask.assign(source.size(), false);
  for (const std::size_t i : final_inliers) result.inlier_mask[i] = true;
  result.iterations = best.iterations;
  return result;
}

}  // namespace kartograf::registration
