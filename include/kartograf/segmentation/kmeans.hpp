#pragma once
// K-Means segmentation baseline (docs/methods.md M1 step 7): Lloyd iterations on the 6-D clustering
// features from k-means++ seeds drawn with a seeded generator, so a run is reproducible.
#include <cstdint>

#include "kartograf/segmentation/clustering_features.hpp"

namespace kartograf::segmentation {

struct KMeansParams {
  std::uint32_t k = 30;  // the paper: 30, 60, 90 (Table 3) and 170..604 (Table 4)
  int max_iterations = 100;
  // Converged when no label changes, or when no centre moves by more than this (feature units).
  double tolerance = 1e-6;
  std::uint64_t seed = 1;
};

// k centres chosen by k-means++ (first uniformly, then each with probability proportional to the
// squared distance to the nearest centre so far). Deterministic for a seed; throws Error unless
// 1 <= k <= features.size(). `method` names the caller in error messages.
CentreMatrix kmeans_plus_plus_seeds(const ClusteringFeatures& features, std::uint32_t k,
                                    std::uint64_t seed, const char* method = "kmeans");

// Lloyd's algorithm. A cluster left empty takes the feature farthest from its centre, so the
// objective (sum of squared distances, objective_history) never increases. Throws Error on
// k = 0, k > features.size(), max_iterations < 1 or a negative tolerance.
ClusteringResult kmeans(const ClusteringFeatures& features, const KMeansParams& params);

}  // namespace kartograf::segmentation
