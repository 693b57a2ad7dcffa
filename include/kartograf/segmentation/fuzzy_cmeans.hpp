#pragma once
// Fuzzy C-Means segmentation baseline (docs/methods.md M1 step 7): alternating membership and
// centre updates on the 6-D clustering features from k-means++ seeds, hard labels by largest
// membership (which is the nearest centre).
#include <cstdint>

#include "kartograf/segmentation/clustering_features.hpp"

namespace kartograf::segmentation {

struct FuzzyCMeansParams {
  std::uint32_t k = 30;
  double fuzzifier = 2.0;  // m > 1; 2 is the usual choice (and MATLAB fcm's default)
  int max_iterations = 100;
  // Converged when an iteration lowers J_m by no more than this fraction (MATLAB fcm stops on an
  // absolute improvement below 1e-5; centre shifts shrink too slowly on flat objectives).
  double tolerance = 1e-5;
  std::uint64_t seed = 1;  // k-means++ initial centres
};

// Memberships u_ik = 1 / sum_j (d_ik / d_jk)^(2 / (m - 1)); a feature on a centre belongs to it
// alone (split evenly among coinciding centres). Rows sum to 1. n x k.
Eigen::MatrixXd fuzzy_memberships(const FeatureMatrix& features, const CentreMatrix& centres,
                                  double fuzzifier);

// objective_history holds J_m = sum_i sum_k u_ik^m d_ik^2 of each iteration (non-increasing).
// Throws Error on k = 0, k > features.size(), m <= 1, max_iterations < 1 or a negative tolerance.
ClusteringResult fuzzy_cmeans(const ClusteringFeatures& features, const FuzzyCMeansParams& params);

}  // namespace kartograf::segmentation
