#include "kartograf/segmentation/som.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/segmentation/kmeans.hpp"

namespace kartograf::segmentation {
namespace {

// Presentations per step of the schedule: rates and radius are constant within one.
constexpr std::size_t kScheduleBlock = 256;
// Neighbours whose weight would fall below this fraction of the learning rate are not updated.
constexpr double kNeighbourhoodCutoff = 1e-6;

int grid_rows_for(const SomParams& params) {
  if (params.grid_rows != 0) {
    require(params.grid_rows >= 1 && params.k % static_cast<std::uint32_t>(params.grid_rows) == 0,
            "som: grid_rows = " + std::to_string(params.grid_rows) +
                " does not divide k = " + std::to_string(params.k) + " nodes (0 picks a grid)");
    return params.grid_rows;
  }
  int rows = 1;  // the largest divisor of k not above sqrt(k)
  for (int r = 1; static_cast<std::uint32_t>(r * r) <= params.k; ++r)
    if (params.k % static_cast<std::uint32_t>(r) == 0) rows = r;
  return rows;
}

void check_schedule(const SomParams& params) {
  const auto rate_ok = [](double r) { return std::isfinite(r) && r > 0 && r <= 1; };
  require(rate_ok(params.initial_learning_rate) && rate_ok(params.final_learning_rate),
          "som: learning rates " + std::to_string(params.initial_learning_rate) + " -> " +
              std::to_string(params.final_learning_rate) + "; expected values in (0, 1]");
  require(std::isfinite(params.initial_radius) && params.initial_radius >= 0,
          "som: initial_radius = " + std::to_string(params.initial_radius) +
              "; expected >= 0 (0: half the grid)");
  require(std::isfinite(params.final_radius) && params.final_radius > 0,
          "som: final_radius = " + std::to_string(params.final_radius) + "; expected > 0");
}

// r0 (r1 / r0)^fraction
double decay(double from, double to, double fraction) {
  return from * std::pow(to / from, fraction);
}

}  // namespace

ClusteringResult som(const ClusteringFeatures& features, const SomParams& params) {
  detail::check_cluster_count("som", params.k, features);
  detail::check_iterations("som", params.max_iterations, params.tolerance);
  check_schedule(params);
  const std::uint32_t k = params.k;
  const int rows = grid_rows_for(params);
  const int cols = static_cast<int>(k) / rows;
  const double initial_radius =
      params.initial_radius > 0 ? params.initial_radius : std::max(1.0, std::max(rows, cols) / 2.0);

  // Squared grid distance between every pair of nodes (node j sits at row j / cols, j % cols).
  std::vector<int> grid_distance(static_cast<std::size_t>(k) * k);
  int max_grid_distance = 0;
  for (std::uint32_t a = 0; a < k; ++a)
    for (std::uint32_t b = 0; b < k; ++b) {
      const int dr = static_cast<int>(a) / cols - static_cast<int>(b) / cols;
      const int dc = static_cast<int>(a) % cols - static_cast<int>(b) % cols;
      grid_distance[a * k + b] = dr * dr + dc * dc;
      max_grid_distance = std::max(max_grid_distance, dr * dr + dc * dc);
    }

  ClusteringResult result;
  CentreMatrix& nodes = result.centres;
  nodes = kmeans_plus_plus_seeds(features, k, params.seed, "som");
  const std::size_t n = features.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::mt19937_64 rng(params.seed ^ 0x9e3779b97f4a7c15ull);  // independent of the seeding draws
  const double total_steps = static_cast<double>(params.max_iterations) * static_cast<double>(n);
  std::vector<double> neighbourhood;  // learning rate x Gaussian weight, by squared grid distance
  int reach = 0;                      // largest squared grid distance still updated

  for (int epoch = 0; epoch < params.max_iterations; ++epoch) {
    for (std::size_t i = n; i > 1; --i)  // Fisher-Yates with the portable uniform draw
      std::swap(order[i - 1],
                order[std::min(i - 1, static_cast<std::size_t>(detail::uniform01(rng) * i))]);
    const CentreMatrix epoch_start = nodes;
    double quantisation = 0;
    for (std::size_t step = 0; step < n; ++step) {
      if (step % kScheduleBlock == 0) {
        const double t =
            (static_cast<double>(epoch) * static_cast<double>(n) + static_cast<double>(step)) /
            total_steps;
        const double rate = decay(params.initial_learning_rate, params.final_learning_rate, t);
        const double radius = decay(initial_radius, params.final_radius, t);
        // exp(-g / (2 r^2)) >= cutoff  <=>  g <= -2 r^2 ln(cutoff)
        reach = static_cast<int>(std::min<double>(
            max_grid_distance, -2.0 * radius * radius * std::log(kNeighbourhoodCutoff)));
        neighbourhood.resize(static_cast<std::size_t>(reach) + 1);
        for (int g = 0; g <= reach; ++g)
          neighbourhood[g] = rate * std::exp(-g / (2.0 * radius * radius));
      }
      const Eigen::Matrix<double, 1, kFeatureDims> x =
          features.values.row(order[step]).cast<double>();
      Eigen::Index best = 0;
      const double best_distance = (nodes.rowwise() - x).rowwise().squaredNorm().minCoeff(&best);
      quantisation += best_distance;
      const int* from_best = &grid_distance[static_cast<std::size_t>(best) * k];
      for (std::uint32_t j = 0; j < k; ++j)
        if (from_best[j] <= reach) nodes.row(j) += neighbourhood[from_best[j]] * (x - nodes.row(j));
    }
    result.objective_history.push_back(quantisation);
    result.iterations = epoch + 1;
    if ((nodes - epoch_start).rowwise().norm().maxCoeff() <= params.tolerance) {
      result.converged = true;
      break;
    }
  }
  NearestCentres nearest = nearest_centres(features.values, nodes);
  result.labels = std::move(nearest.labels);
  for (double d : nearest.squared_distances) result.objective += d;
  return result;
}

}  // namespace kartograf::segmentation
