// SE(3) exp/log and the pose-graph optimiser on graphs with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kartograf/core/error.hpp"
#include "kartograf/core/se3.hpp"
#include "kartograf/mapping/pose_graph.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using se3::Vector6d;

Vector6d random_twist(std::mt19937_64& rng, double rotation, double translation) {
  std::uniform_real_distribution<double> u(-1, 1);
  Vector6d xi;
  for (int k = 0; k < 3; ++k) xi(k) = rotation * u(rng);
  for (int k = 3; k < 6; ++k) xi(k) = translation * u(rng);
  return xi;
}

double pose_distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return se3::log(a.inverse() * b).norm();
}

TEST(Se3, ExpLogRoundTrip) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const double scale = trial < 100 ? 1.5 : 1e-9;  // large angles and the Taylor branch
    const Vector6d xi = random_twist(rng, scale, 2.0 * scale);
    const Vector6d back = se3::log(se3::exp(xi));
    EXPECT_LT((back - xi).norm(), 1e-9 * std::max(1.0, xi.norm())) << xi.transpose();
  }
}

TEST(Se3, ExpMatchesAngleAxisRotation) {
  Vector6d xi;
  xi << 0, 0, M_PI / 2, 1, 0, 0;
  const Eigen::Isometry3d pose = se3::exp(xi);
  EXPECT_NEAR(
      (pose.linear() - Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix())
          .norm(),
      0, 1e-12);
  // Moving 1 m along x while turning 90 degrees about z traces a quarter circle of radius 2/pi.
  EXPECT_NEAR(pose.translation().x(), 2 / M_PI, 1e-12);
  EXPECT_NEAR(pose.translation().y(), 2 / M_PI, 1e-12);
}

TEST(Se3, AdjointConjugates) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Isometry3d t = se3::exp(random_twist(rng, 1.0, 3.0));
    const Vector6d xi = random_twist(rng, 0.5, 0.5);
    const Eigen::Isometry3d lhs = t * se3::exp(xi) * t.inverse();
    const Eigen::Isometry3d rhs = se3::exp(se3::adjoint(t) * xi);
    EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-10);
  }
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
