// Nearest-neighbour correspondence finders for unorganized clouds on every backend: the voxel-hash
// grid (searched on the device) and the k-d tree (on the host) against brute force with the rules
// of kdtree_correspondences.hpp. Stated tolerance: identical correspondence indices (ties broken
// by the lowest index) on every backend. Then the ICP engine with each finder, and colour-gated,
// recovers a known motion of an unorganized cloud.
#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/geometry/backproject.hpp"
#include "kartograf/registration/color_gate.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kartograf/registration/voxel_hash_correspondences.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using registration::AssociationParams;
using registration::CloudView;
using registration::CorrespondenceBuffers;
using registration::CorrespondenceFinder;
using registration::kNoMatch;
using registration::kNotSelected;
using testing::BackendTest;

struct HostClouds {
  std::vector<Point4f> source, source_normals, target, target_normals;
  std::vector<std::uint32_t> source_colors, target_colors;
};

// The rules of kdtree_correspondences.hpp, by exhaustive search in index order.
std::vector<std::int32_t> brute_force(const HostClouds& c, const Eigen::Isometry3d& pose,
                                      const AssociationParams& params, std::uint32_t width) {
  const Eigen::Matrix3d r = pose.linear();
  const Eigen::Vector3d t = pose.translation();
  const double max_sq = params.max_distance * params.max_distance;
  const bool gate = params.max_normal_angle_deg < 180;
  const double min_cosine = std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
  const auto k = static_cast<std::uint32_t>(params.subsample);
  std::vector<std::int32_t> out(c.source.size(), kNoMatch);
  for (std::uint32_t i = 0; i < c.source.size(); ++i) {
    const std::uint32_t row = width == 0 ? 0 : i / width;
    if ((i + row) % k != 0) {
      out[i] = kNotSelected;
      continue;
    }
    const Point4f& p = c.source[i];
    if (!is_valid(p) || (gate && !is_valid(c.source_normals[i]))) continue;
    const auto apply = [&](const Point4f& v, bool translate) {
      Eigen::Vector3d result;
      for (int a = 0; a < 3; ++a) {
        result(a) = r(a, 0) * v.x() + r(a, 1) * v.y() + r(a, 2) * v.z();
        if (translate) result(a) = result(a) + t(a);
      }
      return result;
    };
    const Eigen::Vector3d moved = apply(p, true);
    const Eigen::Vector3d normal =
        gate ? apply(c.source_normals[i], false) : Eigen::Vector3d::Zero();
    double best_sq = max_sq;
    for (std::size_t j = 0; j < c.target.size(); ++j) {
      const Point4f& q = c.target[j];
      if (!is_valid(q)) continue;
      const double dx = moved.x() - q.x(), dy = moved.y() - q.y(), dz = moved.z() - q.z();
      const double d = dx * dx + dy * dy + dz * dz;
      if (!(d < best_sq || (out[i] < 0 && d == best_sq))) continue;
      if (gate) {
        const Point4f& n = c.target_normals[j];
        if (!is_valid(n) ||
            !(normal.x() * n.x() + normal.y() * n.y() + normal.z() * n.z() >= min_cosine)) {
          continue;
        }
      }
      out[i] = static_cast<std::int32_t>(j);
      best_sq = d;
    }
  }
  return out;
}

Eigen::Isometry3d test_motion() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.rotate(
      Eigen::AngleAxisd(3.0 * std::numbers::pi / 180, Eigen::Vector3d(1, 2, 3).normalized()));
  pose.pretranslate(Eigen::Vector3d(0.03, -0.02, 0.04));
  return pose;
}

// Target: random points in a 1.5 m cube (with duplicates and invalid points); source: noisy
// copies of target points moved by the inverse of `pose`, plus stray points.
HostClouds random_clouds(std::mt19937_64& rng, std::size_t target_count, std::size_t source_count,
                         const Eigen::Isometry3d& pose) {
  std::uniform_real_distribution<float> coordinate(-0.75f, 0.75f);
  std::normal_distribution<double> gauss;
  std::uniform_int_distribution<std::size_t> pick(0, target_count - 1);
  const auto random_normal = [&] {
    const Eigen::Vector3d n = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    return Point4f(n.x(), n.y(), n.z(), 0.0f);
  };
  HostClouds c;
  for (std::size_t j = 0; j < target_count; ++j) {
    c.target.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng) + 2.0f, 1.0f);
    c.target_normals.push_back(random_normal());
    if (j % 11 == 10) c.target[j] = c.target[j / 2];  // duplicates: ties
    if (j % 31 == 3) c.target[j] = invalid_point();
    if (j % 23 == 4) c.target_normals[j] = invalid_point();
  }
  const Eigen::Isometry3d inverse = pose.inverse();
  for (std::size_t i = 0; i < source_count; ++i) {
    const std::size_t j = pick(rng);
    Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng) + 2.0);
    Eigen::Vector3d n = random_normal().head<3>().cast<double>();
    if (i % 5 != 0 && is_valid(c.target[j])) {
      p = inverse * (c.target[j].head<3>().cast<double>() +
                     0.01 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
      if (is_valid(c.target_normals[j])) {
        n = (inverse.linear() * (c.target_normals[j].head<3>().cast<double>() +
                                 0.3 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng))))
                .normalized();
      }
    }
    c.source.emplace_back(p.x(), p.y(), p.z(), 1.0f);
    c.source_normals.emplace_back(n.x(), n.y(), n.z(), 0.0f);
    if (i % 43 == 2) c.source[i] = invalid_point();
    if (i % 19 == 5) c.source_normals[i] = invalid_point();
  }
  // Exact ties for some queries: the source point sits where two duplicated targets are.
  for (std::size_t i = 1; i < source_count; i += 97) {
    const std::size_t j = 10 + 11 * (i % (target_count / 11 - 1));
    if (!is_valid(c.target[j])) continue;
    const Eigen::Vector3d p = inverse * c.target[j].head<3>().cast<double>();
    c.source[i] = Point4f(p.x(), p.y(), p.z(), 1.0f);
  }
  return c;
}

struct DeviceClouds {
  DeviceClouds(const compute::Context& context, const HostClouds& h)
      : source(compute::Buffer<Point4f>::from_host(context, h.source)),
        source_normals(compute::Buffer<Point4f>::from_host(context, h.source_normals)),
        target(compute::Buffer<Point4f>::from_host(context, h.target)),
        target_normals(compute::Buffer<Point4f>::from_host(context, h.target_normals)) {
    if (!h.source_colors.empty()) {
      source_colors = compute::Buffer<std::uint32_t>::from_host(context, h.source_colors);
      target_colors = compute::Buffer<std::uint32_t>::from_host(context, h.target_colors);
    }
  }
  CloudView source_view() const {
    return {&source, &source_normals, source_colors.empty() ? nullptr : &source_colors,
            std::nullopt};
  }
  CloudView target_view() const {
    return {&target, &target_normals, target_colors.empty() ? nullptr : &target_colors,
            std::nullopt};
  }
  compute::Buffer<Point4f> source, source_normals, target, target_normals;
  compute::Buffer<std::uint32_t> source_colors, target_colors;
};

std::unique_ptr<CorrespondenceFinder> make_finder(const compute::Context& context, bool kdtree) {
  if (kdtree) return std::make_unique<registration::KdTreeCorrespondences>(context);
  return std::make_unique<registration::VoxelHashCorrespondences>(context);
}

class NearestNeighborTest : public BackendTest {
 protected:
  // Both finders on the same inputs, for each gate configuration, against brute force.
  void expect_brute_force(const HostClouds& host, const Eigen::Isometry3d& pose,
                          std::uint32_t width) {
    const DeviceClouds clouds(context(), host);
    CloudView source = clouds.source_view();
    if (width > 0) {
      source.camera = PinholeIntrinsics{static_cast<int>(width),
                                        static_cast<int>(host.source.size() / width),
                                        500,
                                        500,
                                        width / 2.0,
                                        50};
    }
    for (bool kdtree : {false, true}) {
      const auto finder = make_finder(context(), kdtree);
      finder->prepare(clouds.target_view(), 0);
      CorrespondenceBuffers out;
      for (const AssociationParams params :
           {AssociationParams{0.03, 180, 1, 0}, AssociationParams{0.1, 180, 3, 0},
            AssociationParams{0.06, 30, 2, 0}}) {
        const std::string what = std::string(kdtree ? "k-d tree" : "voxel hash") +
                                 ", max distance " + std::to_string(params.max_distance) +
                                 ", normal gate " + std::to_string(params.max_normal_angle_deg) +
                                 ", 1 in " + std::to_string(params.subsample) + ", width " +
                                 std::to_string(width);
        finder->find(source, clouds.target_view(), pose, params, out);
        const auto actual = out.target_index.to_vector();
        const auto expected = brute_force(host, pose, params, width);
        ASSERT_EQ(actual.size(), expected.size()) << what;
        std::size_t mismatches = 0, matches = 0;
        for (std::size_t i = 0; i < expected.size(); ++i) {
          mismatches += actual[i] != expected[i];
          matches += expected[i] >= 0;
        }
        EXPECT_EQ(mismatches, 0u) << what;
        EXPECT_GT(matches, expected.size() / 10) << what;
      }
    }
  }
};

TEST_P(NearestNeighborTest, BothFindersEqualBruteForceOnRandomClouds) {
  const Eigen::Isometry3d pose = test_motion();
  expect_brute_force(random_clouds(rng, 8000, 6000, pose), pose, 0);
  expect_brute_force(random_clouds(rng, 3000, 60 * 50, pose), pose, 60);  // organized source
}

TEST_P(NearestNeighborTest, FindersAgreeOnSevenScenesFrames) {
  // Frames 100 and 105, one in 25 source points against the whole target (~300k points).
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_7scenes();
  const auto load = [&](const char* name) {
    const PointImage image = geometry::backproject(cpu, testing::read_depth(frames / name), k);
    return std::vector<Point4f>(image.pixels().begin(), image.pixels().end());
  };
  HostClouds host;
  host.source = load("frame-000105.depth.png");
  host.target = load("frame-000100.depth.png");
  const DeviceClouds clouds(context(), host);
  CloudView source = clouds.source_view();
  source.normals = nullptr;
  source.camera = k;
  const AssociationParams params{0.05, 180, 25, 0};
  std::vector<std::int32_t> results[2];
  for (bool kdtree : {false, true}) {
    const auto finder = make_finder(context(), kdtree);
    CorrespondenceBuffers out;
    finder->find(source, clouds.target_view(), Eigen::Isometry3d::Identity(), params, out);
    results[kdtree] = out.target_index.to_vector();
  }
  std::size_t mismatches = 0, matches = 0;
  for (std::size_t i = 0; i < results[0].size(); ++i) {
    mismatches += results[0][i] != results[1][i];
    matches += results[0][i] >= 0;
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(matches, 5000u);
  RecordProperty("matches", std::to_string(matches));
}

TEST_P(NearestNeighborTest, RejectsBadInputs) {
  const HostClouds host = random_clouds(rng, 100, 100, Eigen::Isometry3d::Identity());
  const DeviceClouds clouds(context(), host);
  for (bool kdtree : {false, true}) {
    const auto finder = make_finder(context(), kdtree);
    CorrespondenceBuffers out;
    CloudView source = clouds.source_view();
    const CloudView target = clouds.target_view();
    EXPECT_THROW(finder->find(source, target, Eigen::Isometry3d::Identity(), {0.0, 180, 1, 0}, out),
                 Error);
    EXPECT_THROW(finder->find(source, target, Eigen::Isometry3d::Identity(), {0.1, 180, 0, 0}, out),
                 Error);
    source.normals = nullptr;
    EXPECT_THROW(finder->find(source, target, Eigen::Isometry3d::Identity(), {0.1, 30, 1, 0}, out),
                 Error);
    Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
    bad(0, 3) = std::nan("");
    EXPECT_THROW(finder->find(source, target, bad, {0.1, 180, 1, 0}, out), Error);
  }
  // A target point beyond 2^20 cells of the origin cannot be keyed.
  HostClouds far = host;
  far.target[5] = Point4f(2e5f, 0, 0, 1);
  const DeviceClouds far_clouds(context(), far);
  registration::VoxelHashCorrespondences finder(context());
  CorrespondenceBuffers out;
  EXPECT_THROW(finder.find(far_clouds.source_view(), far_clouds.target_view(),
                           Eigen::Isometry3d::Identity(), {0.1, 180, 1, 0}, out),
               Error);
}

// A room corner (floor and two walls), each surface its own colour, sampled at random; the source
// is the same samples seen from a moved sensor, so the exact motion is the answer.
HostClouds room_corner(std::mt19937_64& rng, std::size_t per_surface,
                       const Eigen::Isometry3d& pose) {
  std::uniform_real_distribution<float> u(0.0f, 2.0f), h(0.0f, 1.5f);
  HostClouds c;
  const std::uint32_t colors[3] = {0x5a7896, 0xc85a3c, 0x3cb45a};
  for (int surface = 0; surface < 3; ++surface) {
    for (std::size_t i = 0; i < per_surface; ++i) {
      Point4f q, n;
      if (surface == 0) {
        q = Point4f(u(rng), u(rng), 0.0f, 1.0f);
        n = Point4f(0, 0, 1, 0);
      } else if (surface == 1) {
        q = Point4f(0.0f, u(rng), h(rng), 1.0f);
        n = Point4f(1, 0, 0, 0);
      } else {
        q = Point4f(u(rng), 0.0f, h(rng), 1.0f);
        n = Point4f(0, 1, 0, 0);
      }
      c.target.push_back(q);
      c.target_normals.push_back(n);
      c.target_colors.push_back(colors[surface]);
    }
  }
  const Eigen::Isometry3d inverse = pose.inverse();
  for (std::size_t j = 0; j < c.target.size(); ++j) {
    const Eigen::Vector3d p = inverse * c.target[j].head<3>().cast<double>();
    const Eigen::Vector3d n = inverse.linear() * c.target_normals[j].head<3>().cast<double>();
    c.source.emplace_back(p.x(), p.y(), p.z(), 1.0f);
    c.source_normals.emplace_back(n.x(), n.y(), n.z(), 0.0f);
  }
  c.source_colors = c.target_colors;
  return c;
}

// Every 10th source point gets the colour of another surface (a wrong colour for the gate).
HostClouds with_wrong_colours(HostClouds c) {
  for (std::size_t i = 3; i < c.source_colors.size(); i += 10) c.source_colors[i] = 0xffff00;
  return c;
}

void expect_recovers(const compute::Context& context, std::unique_ptr<CorrespondenceFinder> finder,
                     registration::ErrorMetric metric, const std::string& what,
                     bool wrong_colours = false) {
  std::mt19937_64 rng(5);
  const Eigen::Isometry3d truth = test_motion();
  const HostClouds corner = room_corner(rng, 3000, truth);
  const DeviceClouds clouds(context, wrong_colours ? with_wrong_colours(corner) : corner);
  registration::IcpParams params;
  params.metric = metric;
  params.max_normal_angle_deg = metric == registration::ErrorMetric::point_to_plane ? 30 : 180;
  params.levels = {{40, 1, 0.15, 0.05}};
  registration::IcpEngine engine(context, params, std::move(finder));
  const CloudView source = clouds.source_view(), target = clouds.target_view();
  const registration::IcpResult result = engine.align(std::span(&source, 1), std::span(&target, 1));
  const Eigen::Isometry3d error = truth.inverse() * result.source_to_target;
  EXPECT_LT(error.translation().norm(), 1e-4) << what;
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle(), 1e-4) << what;
  if (wrong_colours) {
    // The gate rejects the 10% of pairs with a wrong colour, and no right pair (difference 0).
    EXPECT_NEAR(result.fitness, 0.9, 0.002) << what;
  } else {
    EXPECT_GT(result.fitness, 0.98) << what;
  }
}

TEST_P(NearestNeighborTest, IcpEngineRecoversAMotionWithTheVoxelHash) {
  expect_recovers(context(), make_finder(context(), false),
                  registration::ErrorMetric::point_to_plane, "voxel hash, point-to-plane");
}

TEST_P(NearestNeighborTest, IcpEngineRecoversAMotionWithTheKdTree) {
  expect_recovers(context(), make_finder(context(), true),
                  registration::ErrorMetric::point_to_point, "k-d tree, point-to-point");
}

TEST_P(NearestNeighborTest, IcpEngineRecoversAMotionWithColourGatedPairs) {
  expect_recovers(
      context(),
      std::make_unique<registration::ColorGatedFinder>(context(), make_finder(context(), false)),
      registration::ErrorMetric::point_to_point, "colour-gated voxel hash, point-to-point", true);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(NearestNeighborTest);

}  // namespace
}  // namespace kartograf
