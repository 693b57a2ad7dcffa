#include "kartograf/segmentation/kmeans.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <random>
#include <vector>

#include "compute/cpu_parallel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/geometry/segment_moments.hpp"

namespace kartograf::segmentation {
namespace {

// Largest shift of any centre between two sets (feature units).
double max_shift(const CentreMatrix& before, const CentreMatrix& after) {
  return (after - before).rowwise().norm().maxCoeff();
}

// Per-chunk sums of one Lloyd assignment step.
struct AssignmentSums {
  CentreMatrix sums;
  std::vector<std::size_t> counts;
  double objective = 0;
  std::size_t changed = 0;
};

}  // namespace

CentreMatrix kmeans_plus_plus_seeds(const ClusteringFeatures& features, std::uint32_t k,
                                    std::uint64_t seed, const char* method) {
  detail::check_cluster_count(method, k, features);
  const std::size_t n = features.size();
  std::mt19937_64 rng(seed);
  CentreMatrix centres(k, kFeatureDims);
  const auto index_below = [&](std::size_t count) {
    return std::min(count - 1,
                    static_cast<std::size_t>(detail::uniform01(rng) * static_cast<double>(count)));
  };
  std::vector<double> closest(n, std::numeric_limits<double>::infinity());
  std::size_t chosen = index_below(n);
  for (std::uint32_t c = 0;; ++c) {
    centres.row(c) = features.values.row(static_cast<Eigen::Index>(chosen)).cast<double>();
    if (c + 1 == k) break;
    // Squared distance of every feature to its nearest centre so far, summed per chunk.
    std::array<double, detail::kChunks> chunk_totals{};
    const Eigen::RowVectorXd centre = centres.row(c);
    compute::detail::for_each_chunk(
        n, n, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
          double total = 0;
          for (std::size_t i = begin; i < end; ++i) {
            const double d =
                (features.values.row(static_cast<Eigen::Index>(i)).cast<double>() - centre)
                    .squaredNorm();
            closest[i] = std::min(closest[i], d);
            total += closest[i];
          }
          chunk_totals[chunk] = total;
        });
    double total = 0;
    for (double t : chunk_totals) total += t;
    if (!(total > 0)) {  // every feature sits on a centre: any choice is as good
      chosen = index_below(n);
      continue;
    }
    // Draw proportionally to closest[i]; the running sum may fall short of `total` by rounding,
    // so the last feature with a positive weight is the fallback.
    const double target = detail::uniform01(rng) * total;
    double running = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (closest[i] <= 0) continue;
      chosen = i;
      running += closest[i];
      if (running > target) break;
    }
  }
  return centres;
}

ClusteringResult kmeans(const ClusteringFeatures& features, const KMeansParams& params) {
  detail::check_cluster_count("kmeans", params.k, features);
  detail::check_iterations("kmeans", params.max_iterations, params.tolerance);
  const std::size_t n = features.size();
  const std::uint32_t k = params.k;

  ClusteringResult result;
  result.centres = kmeans_plus_plus_seeds(features, k, params.seed);
  result.labels.assign(n, geometry::kNoLabel);
  std::vector<double> distances(n);
  double shift = 0;
  for (int iteration = 1; iteration <= params.max_iterations; ++iteration) {
    std::array<AssignmentSums, detail::kChunks> chunks;
    for (AssignmentSums& c : chunks) {
      c.sums = CentreMatrix::Zero(k, kFeatureDims);
      c.counts.assign(k, 0);
    }
    detail::for_each_distance_block(features.values, result.centres,
                                    [&](std::size_t chunk, Eigen::Index first,
                                        const Eigen::MatrixXd& block, const Eigen::MatrixXd& d) {
                                      AssignmentSums& sums = chunks[chunk];
                                      for (Eigen::Index r = 0; r < d.rows(); ++r) {
                                        Eigen::Index best = 0;
                                        d.row(r).minCoeff(&best);
                                        const auto row = static_cast<std::size_t>(first + r);
                                        const auto label = static_cast<std::uint32_t>(best);
                                        if (result.labels[row] != label) ++sums.changed;
                                        result.labels[row] = label;
                                        distances[row] = d(r, best);
                                        sums.sums.row(best) += block.row(r);
                                        ++sums.counts[label];
                                        sums.objective += d(r, best);
                                      }
                                    });
    AssignmentSums total = std::move(chunks[0]);
    for (std::size_t c = 1; c < detail::kChunks; ++c) {
      total.sums += chunks[c].sums;
      for (std::uint32_t j = 0; j < k; ++j) total.counts[j] += chunks[c].counts[j];
      total.objective += chunks[c].objective;
      total.changed += chunks[c].changed;
    }
    result.objective_history.push_back(total.objective);
    result.iterations = iteration;

    CentreMatrix updated = result.centres;
    for (std::uint32_t j = 0; j < k; ++j) {
      if (total.counts[j] > 0) {
        updated.row(j) = total.sums.row(j) / static_cast<double>(total.counts[j]);
        continue;
      }
      // An empty cluster restarts at the feature farthest from its centre: that feature's
      // distance drops to 0, so the objective still cannot increase.
      const auto farthest = static_cast<std::size_t>(
          std::max_element(distances.begin(), distances.end()) - distances.begin());
      updated.row(j) = features.values.row(static_cast<Eigen::Index>(farthest)).cast<double>();
      distances[farthest] = 0;
    }
    shift = max_shift(result.centres, updated);
    result.centres = std::move(updated);
    if (shift <= params.tolerance) {
      result.converged = true;
      break;
    }
  }
  result.objective = result.objective_history.back();
  if (shift > 0) {  // label with the returned centres
    NearestCentres nearest = nearest_centres(features.values, result.centres);
    result.labels = std::move(nearest.labels);
    result.objective = 0;
    for (double d : nearest.squared_distances) result.objective += d;
  }
  return result;
}

}  // namespace kartograf::segmentation
