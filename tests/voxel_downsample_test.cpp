// Voxel-grid downsampling on every backend vs an all-double reference.
// Stated tolerance: the same voxels in the same order (first-point order) and colours exactly;
// centroids within 1e-6 m and normals within 1e-6 (max abs component), NaN normals alike; two
// runs bit-identical; against the CPU backend the same bounds.
#include <cmath>
#include <map>
#include <string>

#include "kartograf/core/color.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/geometry/voxel_downsample.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using geometry::DeviceCloud;
using geometry::VoxelDownsampleParams;
using testing::BackendTest;

struct HostCloud {
  std::vector<Point4f> points, normals;  // normals empty: none
  std::vector<std::uint32_t> colors;     // empty: none
};

DeviceCloud upload(const compute::Context& context, const HostCloud& host) {
  DeviceCloud cloud;
  cloud.points = compute::Buffer<Point4f>::from_host(context, host.points);
  if (!host.normals.empty())
    cloud.normals = compute::Buffer<Point4f>::from_host(context, host.normals);
  if (!host.colors.empty())
    cloud.colors = compute::Buffer<std::uint32_t>::from_host(context, host.colors);
  return cloud;
}

HostCloud download(const DeviceCloud& cloud) {
  return {cloud.points.to_vector(), cloud.normals.to_vector(), cloud.colors.to_vector()};
}

// The rules of voxel_downsample.hpp in double.
HostCloud reference(const HostCloud& in, float voxel_size) {
  const double s = static_cast<float>(1.0 / voxel_size);
  struct Voxel {
    std::size_t order;
    std::size_t count = 0, normal_count = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), normal_sum = Eigen::Vector3d::Zero();
    std::array<std::uint64_t, 3> color{};
  };
  std::map<std::array<double, 3>, Voxel> voxels;
  for (std::size_t i = 0; i < in.points.size(); ++i) {
    const Point4f& p = in.points[i];
    if (!is_valid(p)) continue;
    const std::array<double, 3> key = {std::floor(p.x() * s), std::floor(p.y() * s),
                                       std::floor(p.z() * s)};
    Voxel& v = voxels.try_emplace(key, Voxel{voxels.size()}).first->second;
    ++v.count;
    v.sum += p.head<3>().cast<double>();
    if (!in.normals.empty() && is_valid(in.normals[i])) {
      ++v.normal_count;
      v.normal_sum += in.normals[i].head<3>().cast<double>();
    }
    for (int c = 0; !in.colors.empty() && c < 3; ++c)
      v.color[c] += (in.colors[i] >> (8 * c)) & 0xff;
  }
  HostCloud out;
  out.points.resize(voxels.size());
  if (!in.normals.empty()) out.normals.resize(voxels.size());
  if (!in.colors.empty()) out.colors.resize(voxels.size());
  for (const auto& [key, v] : voxels) {
    const Eigen::Vector3d centroid = v.sum / static_cast<double>(v.count);
    out.points[v.order] << centroid.cast<float>(), 1.0f;
    if (!in.normals.empty()) {
      const double norm = v.normal_sum.norm();
      out.normals[v.order] = v.normal_count == 0 || norm < 1e-3 * v.normal_count
                                 ? invalid_point()
                                 : Point4f((v.normal_sum / norm).x(), (v.normal_sum / norm).y(),
                                           (v.normal_sum / norm).z(), 0.0f);
    }
    if (!in.colors.empty()) {
      std::uint32_t packed = 0;
      for (int c = 0; c < 3; ++c) {
        packed |= static_cast<std::uint32_t>((2 * v.color[c] + v.count) / (2 * v.count)) << (8 * c);
      }
      out.colors[v.order] = packed;
    }
  }
  return out;
}

// Max abs difference of points and of normals; fails on a different count, NaN pattern or colour.
std::pair<double, double> compare(const HostCloud& actual, const HostCloud& expected,
                                  const std::string& what) {
  EXPECT_EQ(actual.points.size(), expected.points.size()) << what;
  EXPECT_EQ(actual.normals.size(), expected.normals.size()) << what;
  EXPECT_EQ(actual.colors, expected.colors) << what;
  double point_error = 0, normal_error = 0;
  std::size_t nan_mismatches = 0;
  for (std::size_t v = 0; v < std::min(actual.points.size(), expected.points.size()); ++v) {
    EXPECT_EQ(actual.points[v].w(), 1.0f);
    point_error = std::max(point_error,
                           double((actual.points[v] - expected.points[v]).cwiseAbs().maxCoeff()));
    if (v >= std::min(actual.normals.size(), expected.normals.size())) continue;
    if (is_valid(actual.normals[v]) != is_valid(expected.normals[v])) {
      ++nan_mismatches;
    } else if (is_valid(expected.normals[v])) {
      normal_error = std::max(
          normal_error, double((actual.normals[v] - expected.normals[v]).cwiseAbs().maxCoeff()));
    }
  }
  EXPECT_EQ(nan_mismatches, 0u) << what;
  EXPECT_LE(point_error, 1e-6) << what;
  EXPECT_LE(normal_error, 1e-6) << what;
  return {point_error, normal_error};
}

HostCloud random_cloud(std::mt19937_64& rng, std::size_t count, bool normals, bool colors) {
  std::uniform_real_distribution<float> coordinate(-3.0f, 3.0f);
  std::normal_distribution<double> gauss;
  HostCloud cloud;
  for (std::size_t i = 0; i < count; ++i) {
    cloud.points.push_back(i % 41 == 5
                               ? invalid_point()
                               : Point4f(coordinate(rng), coordinate(rng), coordinate(rng) + 2, 1));
    if (normals) {
      const Eigen::Vector3d n =
          Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng) - 2.0).normalized();
      cloud.normals.push_back(i % 17 == 3 ? invalid_point() : Point4f(n.x(), n.y(), n.z(), 0.0f));
    }
    if (colors) cloud.colors.push_back(static_cast<std::uint32_t>(rng()) & 0xffffff);
  }
  return cloud;
}

class VoxelDownsampleTest : public BackendTest {
 protected:
  HostCloud run(const HostCloud& in, float voxel_size) {
    return download(geometry::voxel_downsample(context(), upload(context(), in), {voxel_size}));
  }
};

TEST_P(VoxelDownsampleTest, MatchesReferenceOnRandomClouds) {
  const HostCloud in = random_cloud(rng, 50000, true, true);
  for (float voxel_size : {0.4f, 0.05f, 0.013f}) {
    const std::string what = "voxel " + std::to_string(voxel_size);
    const HostCloud expected = reference(in, voxel_size);
    const auto [point_error, normal_error] = compare(run(in, voxel_size), expected, what);
    RecordProperty("max_point_error_" + what, testing::scientific(point_error));
    RecordProperty("max_normal_error_" + what, testing::scientific(normal_error));
  }
  // Without normals or colours.
  const HostCloud bare{in.points, {}, {}};
  compare(run(bare, 0.1f), reference(bare, 0.1f), "points only");
  const HostCloud coloured{in.points, {}, in.colors};
  compare(run(coloured, 0.1f), reference(coloured, 0.1f), "points and colours");
}

TEST_P(VoxelDownsampleTest, DeterministicAndEqualToTheCpuBackend) {
  const HostCloud in = random_cloud(rng, 30000, true, true);
  geometry::VoxelDownsampler downsampler(context());
  const DeviceCloud cloud = upload(context(), in);
  const HostCloud first = download(downsampler.run(cloud, {0.07f}));
  const HostCloud second = download(downsampler.run(cloud, {0.07f}));
  ASSERT_EQ(first.points.size(), second.points.size());
  EXPECT_EQ(0, std::memcmp(first.points.data(), second.points.data(),
                           first.points.size() * sizeof(Point4f)));
  EXPECT_EQ(0, std::memcmp(first.normals.data(), second.normals.data(),
                           first.normals.size() * sizeof(Point4f)));
  EXPECT_EQ(first.colors, second.colors);
  const compute::Context cpu = compute::Context::cpu();
  const HostCloud on_cpu = download(geometry::voxel_downsample(cpu, upload(cpu, in), {0.07f}));
  compare(first, on_cpu, "vs the CPU backend");
}

TEST_P(VoxelDownsampleTest, MatchesReferenceOnSevenScenesFrame) {
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_7scenes();
  const PointImage points =
      geometry::backproject(cpu, testing::read_depth(frames / "frame-000100.depth.png"), k);
  const NormalImage normals = geometry::estimate_normals(cpu, points);
  const RgbImage colors = testing::read_color(frames / "frame-000100.color.jpg");
  HostCloud in{{points.pixels().begin(), points.pixels().end()},
               {normals.pixels().begin(), normals.pixels().end()},
               {}};
  for (const Rgb8& c : colors.pixels()) in.colors.push_back(pack_rgb(c));
  const HostCloud expected = reference(in, 0.02f);
  const HostCloud actual = run(in, 0.02f);
  const auto [point_error, normal_error] = compare(actual, expected, "7-Scenes frame 100");
  RecordProperty("voxels", std::to_string(actual.points.size()));
  RecordProperty("max_point_error", testing::scientific(point_error));
  RecordProperty("max_normal_error", testing::scientific(normal_error));
}

TEST_P(VoxelDownsampleTest, OpposingNormalsCancelAndOrderFollowsFirstPoints) {
  // Voxel B's first point comes first; voxel A's two normals cancel.
  HostCloud in;
  in.points = {Point4f(1.55f, 0.05f, 0.05f, 1), Point4f(0.05f, 0.05f, 0.05f, 1),
               Point4f(0.06f, 0.05f, 0.05f, 1), Point4f(1.56f, 0.06f, 0.05f, 1)};
  in.normals = {Point4f(0, 0, 1, 0), Point4f(1, 0, 0, 0), Point4f(-1, 0, 0, 0),
                Point4f(0, 0, 1, 0)};
  in.colors = {0x0000ff, 0x00ff00, 0x00fe00, 0x000001};
  const HostCloud out = run(in, 0.1f);
  ASSERT_EQ(out.points.size(), 2u);
  EXPECT_NEAR(out.points[0].x(), 1.555f, 1e-6);
  EXPECT_NEAR(out.points[1].x(), 0.055f, 1e-6);
  EXPECT_EQ(out.normals[0], Point4f(0, 0, 1, 0));
  EXPECT_FALSE(is_valid(out.normals[1]));
  EXPECT_EQ(out.colors[0], 0x000080u);  // (255 + 1) / 2 = 128
  EXPECT_EQ(out.colors[1], 0x00ff00u);  // (255 + 254) / 2 = 254.5 rounds up
}

TEST_P(VoxelDownsampleTest, RejectsBadInputs) {
  HostCloud in = random_cloud(rng, 100, true, false);
  for (float size : {0.0f, -1.0f, std::nanf(""), std::numeric_limits<float>::infinity(), 1e-45f}) {
    EXPECT_THROW(run(in, size), Error) << size;
  }
  in.points[10] = Point4f(1e6f, 0, 0, 1);  // 2^20 voxels of 5 cm are 52 km
  EXPECT_THROW(run(in, 0.05f), Error);
  in.points[10] = Point4f(0, 0, 1, 1);
  in.normals[11] = Point4f(3, 0, 0, 0);
  EXPECT_ERROR_MENTIONS(run(in, 0.05f), "normal");  // a normal of length 3
  in.normals.pop_back();
  EXPECT_THROW(run(in, 0.05f), Error);
  const HostCloud empty = run(HostCloud{}, 0.05f);
  EXPECT_TRUE(empty.points.empty());
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(VoxelDownsampleTest);

}  // namespace
}  // namespace kartograf
