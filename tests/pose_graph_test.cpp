// The pose-graph optimiser on graphs with known answers (SE(3) exp/log: se3_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kartograf/core/error.hpp"
#include "kartograf/core/se3.hpp"
#include "kartograf/mapping/pose_graph.hpp"
#include "se3_random.hpp"
#include "test_support_core.hpp"

namespace kartograf {
namespace {

using se3::Vector6d;
using testing::random_twist;

double pose_distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return se3::log(a.inverse() * b).norm();
}

// A square loop of `n` poses around a 4 m x 4 m room, turning at the corners.
std::vector<Eigen::Isometry3d> loop_trajectory(int n) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < n; ++i) {
    const double angle = 2 * M_PI * i / n;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() =
        Eigen::Vector3d(2 * std::cos(angle), 2 * std::sin(angle), 0.1 * std::sin(3 * angle));
    poses.push_back(pose);
  }
  return poses;
}

mapping::PoseGraphEdge edge_between(const std::vector<Eigen::Isometry3d>& poses, std::size_t i,
                                    std::size_t j, bool loop) {
  mapping::PoseGraphEdge edge;
  edge.from = i;
  edge.to = j;
  edge.measurement = poses[i].inverse() * poses[j];
  edge.information = se3::Matrix6d::Identity() * 1e4;
  edge.loop_closure = loop;
  return edge;
}

TEST(PoseGraph, ExactMeasurementsRecoverPerturbedPoses) {
  const auto truth = loop_trajectory(40);
  mapping::PoseGraph graph;
  std::mt19937_64 rng(3);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    graph.add_node(i == 0 ? truth[0] : truth[i] * se3::exp(random_twist(rng, 0.05, 0.1)));
    if (i > 0) graph.edges.push_back(edge_between(truth, i - 1, i, false));
  }
  graph.edges.push_back(edge_between(truth, truth.size() - 1, 0, true));
  const auto summary = mapping::optimize_pose_graph(graph);
  EXPECT_TRUE(summary.converged);
  EXPECT_LT(summary.final_cost, 1e-12 * summary.initial_cost + 1e-14);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_LT(pose_distance(graph.poses[i], truth[i]), 1e-6) << "node " << i;
  }
}

// Odometry with a constant bias drifts; one loop closure pulls the end back to the start.
TEST(PoseGraph, LoopClosureRemovesDrift) {
  const auto truth = loop_trajectory(60);
  Vector6d bias;
  bias << 0, 0, 0.004, 0.01, 0, 0;  // per step: 0.23 deg of yaw and 1 cm forward
  mapping::PoseGraph graph;
  graph.add_node(truth[0]);
  for (std::size_t i = 1; i < truth.size(); ++i) {
    auto edge = edge_between(truth, i - 1, i, false);
    edge.measurement = edge.measurement * se3::exp(bias);
    graph.edges.push_back(edge);
    graph.add_node(graph.poses.back() * edge.measurement);
  }
  graph.edges.push_back(edge_between(truth, truth.size() - 1, 0, true));
  const double loop_chi2_before = mapping::edge_chi2(graph, graph.edges.back());
  double drift_before = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    drift_before =
        std::max(drift_before, (graph.poses[i].translation() - truth[i].translation()).norm());
  }
  const auto summary = mapping::optimize_pose_graph(graph);
  double drift_after = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    drift_after =
        std::max(drift_after, (graph.poses[i].translation() - truth[i].translation()).norm());
  }
  EXPECT_TRUE(summary.converged);
  EXPECT_EQ(summary.pruned_loop_closures, 0u);
  EXPECT_GT(drift_before, 0.4);
  EXPECT_LT(drift_after, 0.5 * drift_before)
      << "before " << drift_before << " after " << drift_after;
  // Equal information on a ring of n + 1 = 60 edges: to first order the closure error is shared
  // evenly, so the loop edge keeps ~1/60 of it and its chi^2 drops by ~3600 (rotation makes the
  // split uneven: require a 900-fold drop, i.e. at most 1/30 of the error).
  const double loop_chi2_after = mapping::edge_chi2(graph, graph.edges.back());
  EXPECT_LT(loop_chi2_after, loop_chi2_before / 900) << "before " << loop_chi2_before;
}

TEST(PoseGraph, FalseLoopClosureIsPruned) {
  const auto truth = loop_trajectory(30);
  mapping::PoseGraph graph;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    graph.add_node(truth[i]);
    if (i > 0) graph.edges.push_back(edge_between(truth, i - 1, i, false));
  }
  graph.edges.push_back(edge_between(truth, 29, 0, true));
  auto wrong = edge_between(truth, 20, 5, true);
  wrong.measurement =
      wrong.measurement * se3::exp((Vector6d() << 0, 0, 0.8, 1.5, -1, 0).finished());
  graph.edges.push_back(wrong);
  const auto summary = mapping::optimize_pose_graph(graph);
  ASSERT_EQ(summary.pruned_edges.size(), 1u);
  EXPECT_EQ(summary.pruned_edges[0], graph.edges.size());  // the last input edge: the wrong one
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_LT(pose_distance(graph.poses[i], truth[i]), 1e-6) << "node " << i;
  }
}

// A loop edge with no information along x (left to the estimate): poses that disagree with it
// only along x agree with it in every direction it measured.
TEST(PoseGraph, MeasuredResidualIgnoresDirectionsWithoutInformation) {
  std::vector<Eigen::Isometry3d> poses = {Eigen::Isometry3d::Identity(),
                                          Eigen::Isometry3d(Eigen::Translation3d(1.0, 0, 0))};
  mapping::PoseGraphEdge edge{0, 1, Eigen::Isometry3d(Eigen::Translation3d(1.1, 0, 0)),
                              se3::Matrix6d::Identity(), true};
  EXPECT_NEAR(mapping::measured_residual(edge, poses).metres, 0.1, 1e-9);  // fully measured
  edge.information(3, 3) = 0;
  EXPECT_NEAR(mapping::measured_residual(edge, poses).metres, 0.0, 1e-9);
  // A disagreement along y is still seen, and a turn.
  poses[1] = Eigen::Translation3d(1.0, 0.05, 0) * Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ());
  const mapping::EdgeResidual residual = mapping::measured_residual(edge, poses);
  EXPECT_NEAR(residual.metres, 0.05, 0.01);
  EXPECT_NEAR(residual.radians, 0.02, 1e-9);
  EXPECT_THROW(mapping::measured_residual({0, 2, {}, {}, true}, poses), Error);
}

TEST(PoseGraph, RejectsEdgesToMissingNodes) {
  mapping::PoseGraph graph;
  graph.add_node(Eigen::Isometry3d::Identity());
  mapping::PoseGraphEdge edge;
  edge.to = 3;
  graph.edges.push_back(edge);
  EXPECT_ERROR_MENTIONS(mapping::optimize_pose_graph(graph), "missing node");
  mapping::PoseGraph empty;
  EXPECT_THROW(mapping::optimize_pose_graph(empty), Error);
}

}  // namespace
}  // namespace kartograf
