#include "kartograf/mapping/pose_graph.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::mapping {

namespace {

using se3::Matrix6d;
using se3::Vector6d;

Vector6d edge_error(const std::vector<Eigen::Isometry3d>& poses, const PoseGraphEdge& edge) {
  return se3::log(edge.measurement.inverse() * poses[edge.from].inverse() * poses[edge.to]);
}

// First-order inverse right Jacobian of SE(3): I + ad(e) / 2.
Matrix6d inverse_right_jacobian(const Vector6d& e) {
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = se3::hat(e.head<3>());
  ad.bottomRightCorner<3, 3>() = se3::hat(e.head<3>());
  ad.bottomLeftCorner<3, 3>() = se3::hat(e.tail<3>());
  return Matrix6d::Identity() + 0.5 * ad;
}

// IRLS weight and robustified cost of a chi^2 value: Cauchy for loop closures, plain squares else.
struct Robust {
  double weight;
  double cost;
};
Robust robustify(double chi2, bool loop_closure, double kernel) {
  if (!loop_closure || kernel <= 0) return {1.0, 0.5 * chi2};
  const double c2 = kernel * kernel;
  return {1.0 / (1.0 + chi2 / c2), 0.5 * c2 * std::log1p(chi2 / c2)};
}

double total_cost(const PoseGraph& graph, double kernel) {
  double cost = 0;
  for (const auto& edge : graph.edges)
    cost += robustify(edge_chi2(graph, edge), edge.loop_closure, kernel).cost;
  return cost;
}

void validate(const PoseGraph& graph, const PoseGraphParams& options) {
  require(!graph.poses.empty(), "pose graph: no nodes");
  require(options.fixed_node < graph.poses.size(),
          "pose graph: fixed node " + std::to_string(options.fixed_node) + " does not exist");
  for (std::size_t i = 0; i < graph.poses.size(); ++i) {
    require(graph.poses[i].matrix().allFinite(),
            "pose graph: node " + std::to_string(i) + " is not finite");
  }
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& edge = graph.edges[k];
    const std::string name = "pose graph: edge " + std::to_string(k) + " (" +
                             std::to_string(edge.from) + " -> " + std::to_string(edge.to) + ")";
    require(edge.from < graph.poses.size() && edge.to < graph.poses.size(),
            name + " names a missing node");
    require(edge.from != edge.to, name + " joins a node to itself");
    require(edge.measurement.matrix().allFinite() && edge.information.allFinite(),
            name + " has a non-finite measurement or information matrix");
  }
}

struct LinearSystem {
  Eigen::SparseMatrix<double> hessian;
  Eigen::VectorXd gradient;  // J^T W e
};

// Gauss-Newton system over all nodes but the fixed one (block index = node index, shifted).
LinearSystem build_system(const PoseGraph& graph, const PoseGraphParams& options, double kernel) {
  const auto n = graph.poses.size();
  auto block_of = [&](std::size_t node) -> long {
    if (node == options.fixed_node) return -1;
    return static_cast<long>(node < options.fixed_node ? node : node - 1);
  };
  const long unknowns = static_cast<long>(6 * (n - 1));
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(graph.edges.size() * 4 * 36 + static_cast<std::size_t>(unknowns));
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(unknowns);
  for (const auto& edge : graph.edges) {
    const Vector6d e = edge_error(graph.poses, edge);
    const double chi2 = e.dot(edge.information * e);
    const double w = robustify(chi2, edge.loop_closure, kernel).weight;
    const Matrix6d jr_inv = inverse_right_jacobian(e);
    const Matrix6d j_to = jr_inv;
    const Matrix6d j_from =
        -jr_inv * se3::adjoint(graph.poses[edge.to].inverse() * graph.poses[edge.from]);
    const Matrix6d omega = w * edge.information;
    const std::array<std::pair<long, const Matrix6d*>, 2> blocks = {
        std::pair{block_of(edge.from), &j_from}, std::pair{block_of(edge.to), &j_to}};
    for (const auto& [row_block, j_row] : blocks) {
      if (row_block < 0) continue;
      gradient.segment<6>(6 * row_block) += j_row->transpose() * omega * e;
      for (const auto& [col_block, j_col] : blocks) {
        if (col_block < 0) continue;
        const Matrix6d h = j_row->transpose() * omega * *j_col;
        for (int r = 0; r < 6; ++r) {
          for (int c = 0; c < 6; ++c) {
            if (h(r, c) != 0) triplets.emplace_back(6 * row_block + r, 6 * col_block + c, h(r, c));
          }
        }
      }
    }
  }
  LinearSystem system;
  system.hessian.resize(unknowns, unknowns);
  system.hessian.setFromTriplets(triplets.begin(), triplets.end());
  system.gradient = std::move(gradient);
  return system;
}

std::vector<Eigen::Isometry3d> apply_step(const PoseGraph& graph, const Eigen::VectorXd& step,
                                          std::size_t fixed_node) {
  std::vector<Eigen::Isometry3d> poses = graph.poses;
  long block = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i == fixed_node) continue;
    poses[i] = poses[i] * se3::exp(step.segment<6>(6 * block));
    ++block;
  }
  return poses;
}

// Levenberg-Marquardt with Nielsen's damping update, at one loop-closure kernel width.
PoseGraphSummary levenberg_marquardt(PoseGraph& graph, const PoseGraphParams& options,
                                     double kernel) {
  PoseGraphSummary summary;
  double cost = total_cost(graph, kernel);
  summary.initial_cost = cost;
  summary.final_cost = cost;
  if (graph.poses.size() < 2 || graph.edges.empty()) {
    summary.converged = true;
    return summary;
  }
  double lambda = -1;
  double nu = 2;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    summary.iterations = iteration + 1;
    LinearSystem system = build_system(graph, options, kernel);
    Eigen::VectorXd diagonal = system.hessian.diagonal();
    if (lambda < 0) lambda = options.initial_lambda * std::max(1.0, diagonal.maxCoeff());
    bool improved = false;
    while (!improved) {
      Eigen::SparseMatrix<double> damped = system.hessian;
      for (long k = 0; k < damped.rows(); ++k) {
        // Damping proportional to the diagonal, with a floor for unconstrained directions.
        damped.coeffRef(k, k) += lambda * std::max(diagonal(k), 1e-9);
      }
      solver.compute(damped);
      require(solver.info() == Eigen::Success,
              "pose graph: the normal equations are singular (is the graph connected?)");
      const Eigen::VectorXd step = -solver.solve(system.gradient);
      PoseGraph candidate{apply_step(graph, step, options.fixed_node), graph.edges};
      const double new_cost = total_cost(candidate, kernel);
      const double predicted = -(step.dot(system.gradient) + 0.5 * step.dot(system.hessian * step));
      const double rho = predicted > 0 ? (cost - new_cost) / predicted : -1;
      if (new_cost < cost && rho > 0) {
        graph.poses = std::move(candidate.poses);
        const double improvement = cost - new_cost;
        cost = new_cost;
        lambda *= std::max(1.0 / 3.0, 1 - std::pow(2 * rho - 1, 3));
        nu = 2;
        improved = true;
        if (improvement <= options.relative_cost_tolerance * std::max(cost, 1e-300) ||
            step.lpNorm<Eigen::Infinity>() <= options.step_tolerance) {
          summary.converged = true;
        }
      } else {
        if (step.lpNorm<Eigen::Infinity>() <= options.step_tolerance) {
          summary.converged = true;  // no step left to take: a minimum
          break;
        }
        lambda *= nu;
        nu *= 2;
        if (!std::isfinite(lambda) || lambda > 1e32) break;
      }
    }
    summary.final_cost = cost;
    if (summary.converged || !improved) break;
  }
  summary.final_cost = cost;
  return summary;
}

// Graduated non-convexity: a loop closure that disagrees with drifted odometry by many sigmas is
// not an outlier yet. Start with a kernel wide enough to trust every edge, then narrow it by
// quarters to the requested width, so that only edges the converged graph contradicts lose weight.
PoseGraphSummary graduated_optimization(PoseGraph& graph, const PoseGraphParams& options) {
  const double target = options.loop_closure_kernel;
  double widest_chi2 = 0;
  for (const auto& edge : graph.edges) {
    if (edge.loop_closure) widest_chi2 = std::max(widest_chi2, edge_chi2(graph, edge));
  }
  double kernel = target > 0 ? std::max(target, std::sqrt(widest_chi2)) : target;
  PoseGraphSummary summary;
  summary.initial_cost = total_cost(graph, target);
  for (;;) {
    const PoseGraphSummary stage = levenberg_marquardt(graph, options, kernel);
    summary.iterations += stage.iterations;
    summary.converged = stage.converged;
    if (kernel <= target) break;
    kernel = std::max(target, kernel / 4);
  }
  summary.final_cost = total_cost(graph, target);
  return summary;
}

}  // namespace

double edge_chi2(const PoseGraph& graph, const PoseGraphEdge& edge) {
  const Vector6d e = edge_error(graph.poses, edge);
  return e.dot(edge.information * e);
}

PoseGraphSummary optimize_pose_graph(PoseGraph& graph, const PoseGraphParams& options) {
  validate(graph, options);
  PoseGraphSummary summary = graduated_optimization(graph, options);
  if (options.prune_chi2 <= 0) return summary;

  // Loop closures that the optimum still contradicts are false matches: drop them, re-optimise.
  std::vector<PoseGraphEdge> kept;
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& edge = graph.edges[k];
    if (edge.loop_closure && edge_chi2(graph, edge) > options.prune_chi2) {
      summary.pruned_edges.push_back(k);
    } else {
      kept.push_back(edge);
    }
  }
  if (summary.pruned_edges.empty()) return summary;
  graph.edges = std::move(kept);
  const PoseGraphSummary again = levenberg_marquardt(graph, options, options.loop_closure_kernel);
  summary.iterations += again.iterations;
  summary.final_cost = again.final_cost;
  summary.converged = again.converged;
  summary.pruned_loop_closures = summary.pruned_edges.size();
  return summary;
}

EdgeResidual measured_residual(const PoseGraphEdge& edge,
                               const std::vector<Eigen::Isometry3d>& poses) {
  require(edge.from < poses.size() && edge.to < poses.size(),
          "pose graph: edge " + std::to_string(edge.from) + " -> " + std::to_string(edge.to) +
              " names a missing node (" + std::to_string(poses.size()) + " poses)");
  const Vector6d tangent = edge_error(poses, edge);
  const Eigen::SelfAdjointEigenSolver<se3::Matrix6d> eigen(edge.information);
  const double largest = eigen.eigenvalues().maxCoeff();
  se3::Vector6d measured = se3::Vector6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (!(eigen.eigenvalues()(k) > 1e-9 * largest)) continue;
    const se3::Vector6d u = eigen.eigenvectors().col(k);
    measured += u.dot(tangent) * u;
  }
  return {measured.tail<3>().norm(), measured.head<3>().norm()};
}

}  // namespace kartograf::mapping
