// Max-product loopy belief propagation on the place field (voronoi_random_field.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/rooms/voronoi_random_field.hpp"

namespace kartograf::rooms {

namespace {

constexpr std::size_t kL = kPlaceLabels;

void check_field(const PlaceField& field, const std::string& what) {
  const int n = static_cast<int>(field.unary.size());
  for (const auto& [a, b] : field.edges) {
    require(a >= 0 && b >= 0 && a < n && b < n,
            what + ": edge (" + std::to_string(a) + ", " + std::to_string(b) +
                ") names a node outside 0.." + std::to_string(n - 1));
    require(a != b, what + ": edge joins node " + std::to_string(a) + " to itself");
  }
  for (const LabelScores& u : field.unary) {
    for (const double v : u)
      require(std::isfinite(v), what + ": a unary log-potential is not finite");
  }
  require(field.pairwise.allFinite(), what + ": the pairwise log-potential is not finite");
}

void check_params(const BeliefPropagationParams& params, const std::string& what) {
  require(params.max_iterations >= 1, what + ": max_iterations must be >= 1");
  require(std::isfinite(params.damping) && params.damping >= 0 && params.damping < 1,
          what + ": damping must lie in [0, 1)");
  require(std::isfinite(params.tolerance) && params.tolerance >= 0,
          what + ": tolerance must be >= 0");
}

// Directed edge 2e runs first -> second of edge e, 2e + 1 back (so m ^ 1 is m's reverse).
struct DirectedEdges {
  std::vector<std::vector<std::size_t>> incoming;  // per node: the directed edges ending there
  std::vector<std::size_t> source;                 // per directed edge: its start node

  explicit DirectedEdges(const PlaceField& field)
      : incoming(field.unary.size()), source(2 * field.edges.size()) {
    for (std::size_t e = 0; e < field.edges.size(); ++e) {
      const auto a = static_cast<std::size_t>(field.edges[e].first),
                 b = static_cast<std::size_t>(field.edges[e].second);
      source[2 * e] = a;
      source[2 * e + 1] = b;
      incoming[b].push_back(2 * e);
      incoming[a].push_back(2 * e + 1);
    }
  }
  std::size_t count() const { return source.size(); }
};

// Node i's belief: its unary plus the messages it receives.
LabelScores belief_of(const PlaceField& field, const DirectedEdges& edges,
                      const std::vector<LabelScores>& messages, std::size_t i) {
  LabelScores belief = field.unary[i];
  for (const std::size_t m : edges.incoming[i])
    for (std::size_t l = 0; l < kL; ++l) belief[l] += messages[m][l];
  return belief;
}

// One round of damped messages from `messages` into `next`; returns the largest change.
double pass_messages(const PlaceField& field, const DirectedEdges& edges,
                     const std::vector<LabelScores>& belief,
                     const std::vector<LabelScores>& messages, double damping,
                     std::vector<LabelScores>& next) {
  double change = 0;
  for (std::size_t m = 0; m < edges.count(); ++m) {
    // What the source believes without what the target told it, through the compatibility.
    const std::size_t reverse = m ^ 1;
    LabelScores update;
    for (std::size_t to = 0; to < kL; ++to) {
      double best = -std::numeric_limits<double>::infinity();
      for (std::size_t from = 0; from < kL; ++from) {
        best = std::max(best, belief[edges.source[m]][from] - messages[reverse][from] +
                                  field.pairwise(static_cast<int>(from), static_cast<int>(to)));
      }
      update[to] = best;
    }
    const double top = *std::max_element(update.begin(), update.end());  // keep messages bounded
    for (std::size_t l = 0; l < kL; ++l) {
      next[m][l] = (1 - damping) * (update[l] - top) + damping * messages[m][l];
      change = std::max(change, std::abs(next[m][l] - messages[m][l]));
    }
  }
  return change;
}

// Iterated conditional modes from the labels given: each node in turn takes its best label given
// its neighbours'. The score only grows, so this ends at a labelling no single change improves
// (loopy BP that did not converge can decode to a poor one).
void refine_labels(const PlaceField& field, const DirectedEdges& edges, int max_sweeps,
                   PlaceInference& result) {
  const std::size_t n = field.unary.size();
  std::vector<std::vector<std::size_t>> neighbours(n);
  for (std::size_t m = 0; m < edges.count(); ++m)
    neighbours[edges.source[m ^ 1]].push_back(edges.source[m]);
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    int changed = 0;
    for (std::size_t i = 0; i < n; ++i) {
      LabelScores local = field.unary[i];
      for (const std::size_t j : neighbours[i])
        for (std::size_t l = 0; l < kL; ++l)
          local[l] += field.pairwise(static_cast<int>(l), static_cast<int>(result.labels[j]));
      const auto best =
          static_cast<std::size_t>(std::max_element(local.begin(), local.end()) - local.begin());
      if (local[best] > local[static_cast<std::size_t>(result.labels[i])]) {
        result.labels[i] = static_cast<PlaceLabel>(best);
        ++changed;
      }
    }
    result.refined_labels += changed;
    if (changed == 0) break;
  }
}

}  // namespace

double field_score(const PlaceField& field, std::span<const PlaceLabel> labels) {
  require(labels.size() == field.unary.size(), "field_score: " + std::to_string(labels.size()) +
                                                   " labels for " +
                                                   std::to_string(field.unary.size()) + " nodes");
  check_field(field, "field_score");
  double score = 0;
  for (std::size_t i = 0; i < labels.size(); ++i)
    score += field.unary[i][static_cast<std::size_t>(labels[i])];
  for (const auto& [a, b] : field.edges)
    score += field.pairwise(static_cast<int>(labels[static_cast<std::size_t>(a)]),
                            static_cast<int>(labels[static_cast<std::size_t>(b)]));
  return score;
}

PlaceInference max_product_labels(const PlaceField& field, const BeliefPropagationParams& params) {
  const std::string what = "max-product belief propagation";
  check_field(field, what);
  check_params(params, what);
  const std::size_t n = field.unary.size();
  const DirectedEdges edges(field);
  std::vector<LabelScores> messages(edges.count(), LabelScores{}), next(edges.count());
  std::vector<LabelScores> belief(n);
  PlaceInference result;
  for (result.iterations = 1; result.iterations <= params.max_iterations; ++result.iterations) {
    for (std::size_t i = 0; i < n; ++i) belief[i] = belief_of(field, edges, messages, i);
    const double change = pass_messages(field, edges, belief, messages, params.damping, next);
    messages.swap(next);
    if (change <= params.tolerance) {
      result.converged = true;
      break;
    }
  }
  result.iterations = std::min(result.iterations, params.max_iterations);
  result.labels.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const LabelScores b = belief_of(field, edges, messages, i);
    result.labels[i] = static_cast<PlaceLabel>(std::max_element(b.begin(), b.end()) - b.begin());
  }
  refine_labels(field, edges, params.max_iterations, result);
  return result;
}

}  // namespace kartograf::rooms
