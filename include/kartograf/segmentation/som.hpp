#pragma once
// Self-Organizing Map segmentation baseline (docs/methods.md M1 step 7; the paper gives the number
// of neurons, 30/60/90): k nodes on a 1-D or 2-D grid trained online on the 6-D clustering
// features, the learning rate and the Gaussian neighbourhood radius decaying geometrically over the
// epochs; each feature is then labelled with its best-matching node.
#include <cstdint>

#include "kartograf/segmentation/clustering_features.hpp"

namespace kartograf::segmentation {

struct SomParams {
  std::uint32_t k = 30;  // nodes
  // Grid rows; k must be a multiple. 0: the most nearly square grid (30 -> 5x6, 60 -> 6x10,
  // 90 -> 9x10); 1: a line of k nodes.
  int grid_rows = 0;
  int max_iterations = 10;  // epochs: every feature once per epoch, in a seeded random order
  // Converged when no node moved by more than this over an epoch (feature units). Online updates
  // at the final learning rate keep nodes moving, so with the defaults a run usually ends after
  // max_iterations epochs with converged = false (as on a 7-Scenes frame).
  double tolerance = 1e-3;
  double initial_learning_rate = 0.5;
  double final_learning_rate = 0.01;
  double initial_radius = 0;  // grid units; 0: half the longer grid side (at least 1)
  // Small enough that at the end a node barely pulls its grid neighbours (exp(-1/(2 r^2))):
  // the map then quantises like K-Means.
  double final_radius = 0.25;
  std::uint64_t seed = 1;  // k-means++ initial nodes and the presentation order
};

// Rates and radius follow r(t) = r0 (r1 / r0)^(t / T) over all T = epochs x n presentations
// (piecewise constant over blocks of 256). objective: the sum of squared distances to the best
// matching node; objective_history: that sum as met during each epoch's presentations. Throws
// Error on k = 0, k > features.size(), grid_rows not dividing k, max_iterations < 1, a negative
// tolerance, rates outside (0, 1] or non-positive radii.
ClusteringResult som(const ClusteringFeatures& features, const SomParams& params);

}  // namespace kartograf::segmentation
