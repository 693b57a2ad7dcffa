// ICP reductions on every backend vs an all-double two-pass reference.
// Stated tolerance: relative error (Frobenius norm) <= 1e-6 for every sum; pair counts exact.
#include <cmath>
#include <fstream>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/core/pose.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/registration/icp_sums.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using registration::Correspondences;
using testing::BackendTest;

struct HostPairs {
  std::vector<Point4f> source, target, normals;
  std::vector<std::int32_t> correspondences;  // empty: identity
  std::vector<float> weights;                 // empty: all 1
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  double max_distance = std::numeric_limits<double>::infinity();
};

struct ReferencePair {
  Eigen::Vector3d moved, target, normal;
  double weight;
};

std::vector<ReferencePair> reference_pairs(const HostPairs& h, bool need_normals) {
  std::vector<ReferencePair> pairs;
  for (std::size_t i = 0; i < h.source.size(); ++i) {
    const std::int64_t j =
        h.correspondences.empty() ? static_cast<std::int64_t>(i) : h.correspondences[i];
    if (j < 0 || j >= static_cast<std::int64_t>(h.target.size())) continue;
    const double w = h.weights.empty() ? 1.0 : h.weights[i];
    if (!(w > 0) || !is_valid(h.source[i]) || !is_valid(h.target[j])) continue;
    if (need_normals && !is_valid(h.normals[j])) continue;
    ReferencePair pair{h.transform * h.source[i].head<3>().cast<double>(),
                       h.target[j].head<3>().cast<double>(),
                       need_normals ? Eigen::Vector3d(h.normals[j].head<3>().cast<double>())
                                    : Eigen::Vector3d::Zero(),
                       w};
    if ((pair.moved - pair.target).norm() > h.max_distance) continue;
    pairs.push_back(pair);
  }
  return pairs;
}

template <class Matrix>
double relative_error(const Matrix& actual, const Matrix& expected) {
  return (actual - expected).norm() / std::max(expected.norm(), 1e-300);
}

struct Uploaded {
  compute::Buffer<Point4f> source, target, normals;
  compute::Buffer<std::int32_t> correspondences;
  compute::Buffer<float> weights;
  Correspondences view;
};

std::unique_ptr<Uploaded> upload(const compute::Context& context, const HostPairs& h) {
  auto u = std::make_unique<Uploaded>();
  u->source = compute::Buffer<Point4f>::from_host(context, h.source);
  u->target = compute::Buffer<Point4f>::from_host(context, h.target);
  u->view.source = &u->source;
  u->view.target = &u->target;
  if (!h.normals.empty()) {
    u->normals = compute::Buffer<Point4f>::from_host(context, h.normals);
    u->view.target_normals = &u->normals;
  }
  if (!h.correspondences.empty()) {
    u->correspondences = compute::Buffer<std::int32_t>::from_host(context, h.correspondences);
    u->view.correspondences = &u->correspondences;
  }
  if (!h.weights.empty()) {
    u->weights = compute::Buffer<float>::from_host(context, h.weights);
    u->view.weights = &u->weights;
  }
  u->view.source_to_target = h.transform;
  u->view.max_distance = h.max_distance;
  return u;
}

// Checks both reductions against the reference; returns the worst relative error seen.
double check_against_reference(const compute::Context& context, const HostPairs& h,
                               const std::string& what) {
  auto uploaded = upload(context, h);
  registration::IcpReduction reduction(context);
  double worst = 0;

  const auto pairs = reference_pairs(h, false);
  double weight = 0, squared_error = 0;
  Eigen::Vector3d mean_p = Eigen::Vector3d::Zero(), mean_q = Eigen::Vector3d::Zero();
  for (const auto& p : pairs) {
    weight += p.weight;
    mean_p += p.weight * p.moved;
    mean_q += p.weight * p.target;
    squared_error += p.weight * (p.moved - p.target).squaredNorm();
  }
  mean_p /= weight;
  mean_q /= weight;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& p : pairs)
    covariance += p.weight * (p.moved - mean_p) * (p.target - mean_q).transpose();

  // A rough pivot, as ICP would pass: the first source point.
  const Eigen::Vector3d pivot = h.transform * h.source[0].head<3>().cast<double>();
  const auto sums = reduction.point_to_point(
      uploaded->view, pivot.array().isNaN().any() ? Eigen::Vector3d::Zero() : pivot,
      Eigen::Vector3d(0.5, 0.5, 2.0));
  EXPECT_EQ(sums.pair_count, pairs.size()) << what;
  worst =
      std::max({worst, std::fabs(sums.weight_sum - weight) / weight,
                relative_error(sums.source_mean, mean_p), relative_error(sums.target_mean, mean_q),
                relative_error(sums.cross_covariance, covariance),
                std::fabs(sums.squared_error_sum - squared_error) / squared_error});

  if (!h.normals.empty()) {
    const auto plane_pairs = reference_pairs(h, true);
    Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> jtr = Eigen::Matrix<double, 6, 1>::Zero();
    double r2 = 0;
    const Eigen::Vector3d plane_pivot = mean_p;
    for (const auto& p : plane_pairs) {
      Eigen::Matrix<double, 6, 1> j;
      j << (p.moved - plane_pivot).cross(p.normal), p.normal;
      const double r = (p.moved - p.target).dot(p.normal);
      jtj += p.weight * j * j.transpose();
      jtr += p.weight * j * r;
      r2 += p.weight * r * r;
    }
    const auto system = reduction.point_to_plane(uploaded->view, plane_pivot);
    EXPECT_EQ(system.pair_count, plane_pairs.size()) << what;
    worst = std::max({worst, relative_error(system.jtj, jtj), relative_error(system.jtr, jtr),
                      std::fabs(system.squared_error_sum - r2) / r2});
  }
  EXPECT_LE(worst, 1e-6) << what;
  return worst;
}

class IcpSumsTest : public BackendTest {};

TEST_P(IcpSumsTest, MatchesReferenceOnRandomPairs) {
  for (std::size_t count : {std::size_t{1}, std::size_t{1000}, std::size_t{307200}}) {
    HostPairs h;
    std::uniform_real_distribution<float> coordinate(-1.5f, 1.5f), unit(0.0f, 1.0f);
    std::normal_distribution<float> noise(0.0f, 0.001f);
    const Eigen::Isometry3d truth = Eigen::Translation3d(0.1, -0.05, 0.2) *
                                    Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 2, 3).normalized());
    std::vector<std::int32_t> order(count);
    for (std::size_t i = 0; i < count; ++i) order[i] = static_cast<std::int32_t>(count - 1 - i);
    h.source.resize(count);
    h.target.resize(count);
    h.normals.resize(count);
    h.correspondences.resize(count);
    h.weights.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      h.source[i] =
          Point4f(coordinate(rng) + 1.0f, coordinate(rng) + 0.5f, coordinate(rng) + 3.0f, 1.0f);
      if (count > 1 && i % 97 == 5) h.source[i] = invalid_point();
      const Eigen::Vector3d moved = truth * h.source[i].head<3>().cast<double>();
      const std::size_t j = order[i];
      const Eigen::Vector3d noisy = moved + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      h.target[j] = Eigen::Vector4d(noisy.x(), noisy.y(), noisy.z(), 1.0).cast<float>();
      const Eigen::Vector3d n =
          Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng)).normalized();
      h.normals[j] = Eigen::Vector4d(n.x(), n.y(), n.z(), 0.0).cast<float>();
      h.correspondences[i] = (count > 1 && i % 31 == 7) ? -1 : order[i];
      h.weights[i] = (count > 1 && i % 13 == 3) ? 0.0f : unit(rng) + 0.1f;
    }
    // Near convergence, as in the last ICP iterations: residuals of millimetres.
    h.transform = Eigen::Translation3d(0.0005, 0, 0) * truth;
    h.max_distance = count > 1 ? 0.004 : 1.0;
    const double worst = check_against_reference(context(), h, std::to_string(count) + " pairs");
    RecordProperty("max_relative_error_" + std::to_string(count), testing::scientific(worst));
  }
}

TEST_P(IcpSumsTest, IdentityPairingWithoutOptionalBuffers) {
  HostPairs h;
  std::uniform_real_distribution<float> coordinate(-2.0f, 2.0f);
  for (int i = 0; i < 5000; ++i) {
    h.source.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng) + 4.0f, 1.0f);
    h.target.emplace_back(h.source.back() + Point4f(0.01f, -0.02f, 0.005f, 0.0f));
  }
  h.target.resize(4000);  // sources beyond the target count have no pair
  check_against_reference(context(), h, "identity pairing");
}

TEST_P(IcpSumsTest, MatchesReferenceOnSevenScenesFramePair) {
  // Frame 0 -> frame 10 with the ground-truth relative pose and projective association, as the
  // first ICP iteration on real Kinect data would see them.
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_7scenes();
  const PointImage source =
      geometry::backproject(cpu, testing::read_depth(frames / "frame-000000.depth.png"), k);
  const PointImage target =
      geometry::backproject(cpu, testing::read_depth(frames / "frame-000010.depth.png"), k);
  const NormalImage normals = geometry::estimate_normals(cpu, target);
  HostPairs h;
  h.source.assign(source.pixels().begin(), source.pixels().end());
  h.target.assign(target.pixels().begin(), target.pixels().end());
  h.normals.assign(normals.pixels().begin(), normals.pixels().end());
  h.transform = testing::read_pose(frames / "frame-000010.pose.txt").inverse() *
                testing::read_pose(frames / "frame-000000.pose.txt");
  h.max_distance = 0.05;
  h.correspondences.assign(h.source.size(), -1);
  for (std::size_t i = 0; i < h.source.size(); ++i) {
    if (!is_valid(h.source[i])) continue;
    const Eigen::Vector3d p = h.transform * h.source[i].head<3>().cast<double>();
    const long u = std::lround(k.fx * p.x() / p.z() + k.cx),
               v = std::lround(k.fy * p.y() / p.z() + k.cy);
    if (p.z() > 0 && u >= 0 && v >= 0 && u < k.width && v < k.height)
      h.correspondences[i] = static_cast<std::int32_t>(v * k.width + u);
  }
  const double worst = check_against_reference(context(), h, "7-Scenes 0 -> 10");
  RecordProperty("max_relative_error_7scenes", testing::scientific(worst));
}

TEST_P(IcpSumsTest, ReproducibleRunToRun) {
  HostPairs h;
  std::uniform_real_distribution<float> coordinate(-2.0f, 2.0f);
  for (int i = 0; i < 100000; ++i) {
    h.source.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng) + 4.0f, 1.0f);
    h.target.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng) + 4.0f, 1.0f);
  }
  auto uploaded = upload(context(), h);
  registration::IcpReduction reduction(context());
  const auto first = reduction.point_to_point(uploaded->view);
  for (int run = 0; run < 3; ++run) {
    const auto again = reduction.point_to_point(uploaded->view);
    EXPECT_EQ(again.cross_covariance, first.cross_covariance);
    EXPECT_EQ(again.squared_error_sum, first.squared_error_sum);
  }
}

TEST_P(IcpSumsTest, RejectsMismatchedBuffers) {
  HostPairs h;
  h.source.assign(10, Point4f(0, 0, 1, 1));
  h.target.assign(10, Point4f(0, 0, 1, 1));
  h.weights.assign(9, 1.0f);
  auto uploaded = upload(context(), h);
  registration::IcpReduction reduction(context());
  EXPECT_THROW(reduction.point_to_point(uploaded->view), Error);
  uploaded->view.weights = nullptr;
  EXPECT_THROW(reduction.point_to_plane(uploaded->view), Error);  // no normals
  uploaded->view.max_distance = -1;
  EXPECT_THROW(reduction.point_to_point(uploaded->view), Error);
}

TEST_P(IcpSumsTest, RobustWeightsCountsAndUnweightedSums) {
  // Pairs near convergence plus planted outliers (centimetres off); entries kNotSelected and
  // kNoMatch; Huber and Tukey. Reference: the kernel of robust_kernel.hpp on each pair in double.
  HostPairs h;
  std::uniform_real_distribution<float> coordinate(-1.5f, 1.5f), unit(0.0f, 1.0f);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  const std::size_t count = 20000;
  for (std::size_t i = 0; i < count; ++i) {
    const Point4f p(coordinate(rng) + 1.0f, coordinate(rng), coordinate(rng) + 3.0f, 1.0f);
    h.source.push_back(i % 89 == 4 ? invalid_point() : p);
    const float offset = i % 17 == 0 ? 0.05f : 0.0f;  // outliers
    h.target.push_back(p + Point4f(noise(rng) + offset, noise(rng), noise(rng) - offset, 0.0f));
    const Eigen::Vector3d n =
        Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng)).normalized();
    h.normals.push_back(Eigen::Vector4d(n.x(), n.y(), n.z(), 0.0).cast<float>());
    h.correspondences.push_back(i % 5 == 1   ? registration::kNotSelected
                                : i % 7 == 2 ? registration::kNoMatch
                                             : static_cast<std::int32_t>(i));
  }
  h.max_distance = 0.2;
  auto uploaded = upload(context(), h);
  registration::IcpReduction reduction(context());
  const Eigen::Vector3d pivot(1.0, 0.0, 3.0);
  for (const auto kernel : {registration::RobustKernel::none, registration::RobustKernel::huber,
                            registration::RobustKernel::tukey}) {
    const registration::RobustLoss loss{kernel, 0.01};
    uploaded->view.robust = loss;
    std::uint64_t considered = 0, pairs = 0;
    double weight = 0, plane_weight = 0, squared = 0, plane_squared = 0;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> jtr = Eigen::Matrix<double, 6, 1>::Zero();
    std::vector<std::pair<Eigen::Vector3d, double>> weighted;  // source point, weight
    for (std::size_t i = 0; i < count; ++i) {
      if (!is_valid(h.source[i]) || h.correspondences[i] == registration::kNotSelected) continue;
      ++considered;
      if (h.correspondences[i] < 0) continue;
      const Eigen::Vector3d p = h.source[i].head<3>().cast<double>(),
                            q = h.target[i].head<3>().cast<double>();
      const Eigen::Vector3d n = h.normals[i].head<3>().cast<double>();
      ++pairs;
      const double w = registration::robust_weight(loss, (p - q).norm());
      weight += w;
      mean += w * p;
      squared += (p - q).squaredNorm();
      weighted.emplace_back(p, w);
      const double r = (p - q).dot(n), wp = registration::robust_weight(loss, r);
      Eigen::Matrix<double, 6, 1> j;
      j << (p - pivot).cross(n), n;
      jtj += wp * j * j.transpose();
      jtr += wp * j * r;
      plane_weight += wp;
      plane_squared += r * r;
    }
    mean /= weight;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const auto& [p, w] : weighted) scatter += w * (p - mean) * (p - mean).transpose();

    const auto sums = reduction.point_to_point(uploaded->view, pivot, pivot);
    EXPECT_EQ(sums.considered_count, considered);
    EXPECT_EQ(sums.pair_count, pairs);
    EXPECT_NEAR(sums.weight_sum, weight, 1e-9 * weight);
    EXPECT_NEAR(sums.unweighted_squared_error_sum, squared, 1e-9 * squared);
    EXPECT_LE(relative_error(sums.source_scatter, scatter), 1e-6);
    const auto system = reduction.point_to_plane(uploaded->view, pivot);
    EXPECT_EQ(system.considered_count, considered);
    EXPECT_EQ(system.pair_count, pairs);
    EXPECT_NEAR(system.weight_sum, plane_weight, 1e-9 * plane_weight);
    EXPECT_NEAR(system.unweighted_squared_error_sum, plane_squared, 1e-9 * plane_squared);
    EXPECT_LE(relative_error(system.jtj, jtj), 1e-6);
    EXPECT_LE(relative_error(system.jtr, jtr), 1e-6);
    if (kernel == registration::RobustKernel::tukey) {
      EXPECT_LT(weight, 0.95 * static_cast<double>(pairs));  // the outliers weigh nothing
    }
  }
  uploaded->view.robust = {registration::RobustKernel::huber, 0.0};
  EXPECT_THROW(reduction.point_to_point(uploaded->view), Error);
}

TEST(RobustKernels, KnownWeights) {
  const registration::RobustLoss huber{registration::RobustKernel::huber, 0.02};
  const registration::RobustLoss tukey{registration::RobustKernel::tukey, 0.02};
  EXPECT_DOUBLE_EQ(registration::robust_weight(huber, -0.01), 1.0);
  EXPECT_DOUBLE_EQ(registration::robust_weight(huber, 0.08), 0.25);
  EXPECT_DOUBLE_EQ(registration::robust_weight(tukey, 0.01), 0.5625);  // (1 - 1/4)^2
  EXPECT_DOUBLE_EQ(registration::robust_weight(tukey, -0.02), 0.0);
  EXPECT_DOUBLE_EQ(registration::robust_weight({}, 5.0), 1.0);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(IcpSumsTest);

}  // namespace
}  // namespace kartograf
