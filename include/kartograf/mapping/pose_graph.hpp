#pragma once
// Global consistency for a trajectory (the "simultaneous multi-view registration" the M3 paper
// names as future work): nodes are camera-to-world poses, edges relative measurements
// Z_ij ~ T_i^-1 T_j with a 6x6 information matrix (tangent order (omega, v), e.g. ICP's J^T J).
// Levenberg-Marquardt on SE(3) with right-multiplied increments; each step solves the sparse normal
// equations with Eigen's SimplicialLDLT. Loop-closure edges go through a robust (Cauchy) kernel,
// and those still inconsistent after optimisation are pruned and the graph re-optimised.
#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/se3.hpp"

namespace kartograf::mapping {

struct PoseGraphEdge {
  std::size_t from = 0;
  std::size_t to = 0;
  Eigen::Isometry3d measurement = Eigen::Isometry3d::Identity();  // T_from^-1 T_to
  se3::Matrix6d information = se3::Matrix6d::Identity();
  bool loop_closure = false;  // odometry edges are trusted; loop closures may be outliers
};

struct PoseGraph {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<PoseGraphEdge> edges;

  std::size_t add_node(const Eigen::Isometry3d& pose) {
    poses.push_back(pose);
    return poses.size() - 1;
  }
};

struct PoseGraphParams {
  int max_iterations = 100;
  double initial_lambda = 1e-6;            // relative to the diagonal of J^T J
  double relative_cost_tolerance = 1e-10;  // stop when a step improves the cost by less
  double step_tolerance = 1e-10;           // or when the largest increment is this small
  // Cauchy kernel width for loop closures, in units of the information-weighted residual (chi).
  double loop_closure_kernel = 1.0;
  // After optimisation, loop closures whose chi^2 exceeds this are removed (0 keeps them all).
  double prune_chi2 = 25.0;
  std::size_t fixed_node = 0;  // the gauge: this pose does not move
};

struct PoseGraphSummary {
  int iterations = 0;
  double initial_cost = 0;  // 1/2 sum of robustified chi^2 before and after
  double final_cost = 0;
  bool converged = false;
  std::size_t pruned_loop_closures = 0;
  std::vector<std::size_t> pruned_edges;  // indices into the input edge list
};

// Optimises graph.poses in place; pruned edges are removed from graph.edges. Throws Error on an
// edge naming a missing node, a non-finite measurement or information matrix, or an empty graph.
PoseGraphSummary optimize_pose_graph(PoseGraph& graph, const PoseGraphParams& options = {});

// chi^2 = e^T Omega e of one edge at the current poses, e = log(Z^-1 T_i^-1 T_j).
double edge_chi2(const PoseGraph& graph, const PoseGraphEdge& edge);

// How far the poses disagree with an edge in the directions it measured: e = log(Z^-1 T_i^-1 T_j)
// projected on the range of the edge's information (eigenvalues above 1e-9 x the largest). An
// edge with no information in a direction (a loop closure that left it to the estimate) has no
// say in it, so the poses moving there is no disagreement.
struct EdgeResidual {
  double metres = 0;   // |v| of the projected (omega, v)
  double radians = 0;  // |omega|
};
EdgeResidual measured_residual(const PoseGraphEdge& edge,
                               const std::vector<Eigen::Isometry3d>& poses);

}  // namespace kartograf::mapping
