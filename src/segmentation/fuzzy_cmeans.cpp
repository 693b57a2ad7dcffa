#include "kartograf/segmentation/fuzzy_cmeans.hpp"

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/segmentation/kmeans.hpp"

namespace kartograf::segmentation {
namespace {

void check_fuzzifier(double m) {
  require(std::isfinite(m) && m > 1,
          "fuzzy_cmeans: fuzzifier m = " + std::to_string(m) + "; expected a finite value > 1");
}

// Memberships of a block from its squared distances D: u_j = w_j / sum w with
// w_j = (D_min / D_j)^(1 / (m - 1)), all in (0, 1], so nothing overflows; a feature on a centre
// (D_j = D_min = 0) gets w = 1 there and 0 elsewhere.
void memberships(const Eigen::MatrixXd& squared_distances, double m, Eigen::MatrixXd& u) {
  const double exponent = 1.0 / (m - 1.0);
  u.resize(squared_distances.rows(), squared_distances.cols());
  for (Eigen::Index r = 0; r < u.rows(); ++r) {
    const double nearest = squared_distances.row(r).minCoeff();
    double sum = 0;
    for (Eigen::Index j = 0; j < u.cols(); ++j) {
      const double d = squared_distances(r, j);
      const double ratio = d <= nearest ? 1.0 : nearest / d;
      u(r, j) = exponent == 1.0 ? ratio : std::pow(ratio, exponent);
      sum += u(r, j);
    }
    u.row(r) /= sum;
  }
}

// One pass over the features with fixed centres: the centre update's numerators and
// denominators, J_m, and the nearest centre of each feature.
struct FcmPass {
  CentreMatrix numerators;
  Eigen::VectorXd denominators;
  double objective = 0;
};

FcmPass fcm_pass(const FeatureMatrix& features, const CentreMatrix& centres, double m,
                 std::vector<std::uint32_t>& labels) {
  const Eigen::Index k = centres.rows();
  std::array<FcmPass, detail::kChunks> chunks;
  for (FcmPass& c : chunks) {
    c.numerators = CentreMatrix::Zero(k, kFeatureDims);
    c.denominators = Eigen::VectorXd::Zero(k);
  }
  labels.resize(static_cast<std::size_t>(features.rows()));
  detail::for_each_distance_block(
      features, centres,
      [&](std::size_t chunk, Eigen::Index first, const Eigen::MatrixXd& block,
          const Eigen::MatrixXd& d) {
        Eigen::MatrixXd u;
        memberships(d, m, u);
        const Eigen::MatrixXd um = m == 2.0 ? u.cwiseAbs2().eval() : u.array().pow(m).matrix();
        FcmPass& sums = chunks[chunk];
        sums.numerators.noalias() += um.transpose() * block;
        sums.denominators += um.colwise().sum().transpose();
        sums.objective += um.cwiseProduct(d).sum();
        for (Eigen::Index r = 0; r < d.rows(); ++r) {
          Eigen::Index best = 0;
          d.row(r).minCoeff(&best);  // largest membership = nearest centre
          labels[static_cast<std::size_t>(first + r)] = static_cast<std::uint32_t>(best);
        }
      });
  FcmPass total = std::move(chunks[0]);
  for (std::size_t c = 1; c < detail::kChunks; ++c) {
    total.numerators += chunks[c].numerators;
    total.denominators += chunks[c].denominators;
    total.objective += chunks[c].objective;
  }
  return total;
}

}  // namespace

Eigen::MatrixXd fuzzy_memberships(const FeatureMatrix& features, const CentreMatrix& centres,
                                  double fuzzifier) {
  check_fuzzifier(fuzzifier);
  require(centres.rows() > 0, "fuzzy_memberships: no centres");
  Eigen::MatrixXd all(features.rows(), centres.rows());
  detail::for_each_distance_block(
      features, centres,
      [&](std::size_t, Eigen::Index first, const Eigen::MatrixXd&, const Eigen::MatrixXd& d) {
        Eigen::MatrixXd u;
        memberships(d, fuzzifier, u);
        all.middleRows(first, u.rows()) = u;
      });
  return all;
}

ClusteringResult fuzzy_cmeans(const ClusteringFeatures& features, const FuzzyCMeansParams& params) {
  detail::check_cluster_count("fuzzy_cmeans", params.k, features);
  detail::check_iterations("fuzzy_cmeans", params.max_iterations, params.tolerance);
  check_fuzzifier(params.fuzzifier);
  ClusteringResult result;
  result.centres = kmeans_plus_plus_seeds(features, params.k, params.seed, "fuzzy_cmeans");
  for (int iteration = 1; iteration <= params.max_iterations; ++iteration) {
    const FcmPass pass = fcm_pass(features.values, result.centres, params.fuzzifier, result.labels);
    result.objective_history.push_back(pass.objective);
    result.iterations = iteration;
    for (Eigen::Index j = 0; j < result.centres.rows(); ++j)  // a centre nobody belongs to stays
      if (pass.denominators(j) > 0)
        result.centres.row(j) = pass.numerators.row(j) / pass.denominators(j);
    const std::size_t done = result.objective_history.size();
    if (done >= 2 && result.objective_history[done - 2] - pass.objective <=
                         params.tolerance * result.objective_history[done - 2]) {
      result.converged = true;
      break;
    }
  }
  // J_m and the hard labels for the returned centres.
  result.objective =
      fcm_pass(features.values, result.centres, params.fuzzifier, result.labels).objective;
  return result;
}

}  // namespace kartograf::segmentation
