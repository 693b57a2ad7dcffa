// Uniform 1-in-k subsampling of unorganized clouds on every backend: an exact copy of points
// 0, k, 2k, ... with their normals and colours (bit for bit, NaN included).
#include <cstring>
#include <string>

#include "kartograf/geometry/subsample.hpp"
#include "kartograf/registration/correspondence_finder.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using geometry::DeviceCloud;
using testing::BackendTest;

bool same_bits(const Point4f& a, const Point4f& b) {
  return std::memcmp(a.data(), b.data(), sizeof(Point4f)) == 0;
}

class SubsampleTest : public BackendTest {};

TEST_P(SubsampleTest, KeepsEveryKthPointWithItsAttributes) {
  std::uniform_real_distribution<float> coordinate(-2.0f, 2.0f);
  for (std::size_t count : {0u, 1u, 999u, 1000u, 20011u}) {
    std::vector<Point4f> points(count), normals(count);
    std::vector<std::uint32_t> colors(count);
    for (std::size_t i = 0; i < count; ++i) {
      points[i] = i % 13 == 4 ? invalid_point()
                              : Point4f(coordinate(rng), coordinate(rng), coordinate(rng), 1);
      normals[i] = Point4f(coordinate(rng), coordinate(rng), coordinate(rng), 0);
      colors[i] = static_cast<std::uint32_t>(rng()) & 0xffffff;
    }
    DeviceCloud cloud;
    cloud.points = compute::Buffer<Point4f>::from_host(context(), points);
    cloud.normals = compute::Buffer<Point4f>::from_host(context(), normals);
    cloud.colors = compute::Buffer<std::uint32_t>::from_host(context(), colors);
    for (int k : {1, 3, 10}) {
      const std::string what = std::to_string(count) + " points, k = " + std::to_string(k);
      const DeviceCloud out = geometry::subsample(context(), cloud, k);
      const std::size_t expected = (count + k - 1) / k;
      ASSERT_EQ(out.size(), expected) << what;
      ASSERT_EQ(out.normals.size(), expected) << what;
      ASSERT_EQ(out.colors.size(), expected) << what;
      const auto p = out.points.to_vector();
      const auto n = out.normals.to_vector();
      const auto c = out.colors.to_vector();
      for (std::size_t m = 0; m < expected; ++m) {
        // The selection of the ICP engine for an unorganized cloud.
        ASSERT_TRUE(registration::is_selected(static_cast<std::uint32_t>(m * k), 0, k));
        ASSERT_TRUE(same_bits(p[m], points[m * k])) << what << ", point " << m;
        ASSERT_TRUE(same_bits(n[m], normals[m * k])) << what << ", normal " << m;
        ASSERT_EQ(c[m], colors[m * k]) << what << ", colour " << m;
      }
    }
  }
}

TEST_P(SubsampleTest, PointsOnlyAndHostRoundTrip) {
  PointCloud host;
  for (int i = 0; i < 100; ++i) {
    host.points.emplace_back(float(i), 0.5f * i, -1.0f);
    host.colors.push_back({static_cast<std::uint8_t>(i), 7, 200});
  }
  const DeviceCloud cloud = DeviceCloud::from_host(context(), host);
  EXPECT_FALSE(cloud.has_normals());
  const PointCloud back = geometry::subsample(context(), cloud, 7).to_host();
  ASSERT_EQ(back.size(), 15u);
  EXPECT_FALSE(back.has_normals());
  for (std::size_t m = 0; m < back.size(); ++m) {
    EXPECT_EQ(back.points[m], host.points[m * 7]);
    EXPECT_EQ(back.colors[m], host.colors[m * 7]);
  }
}

TEST_P(SubsampleTest, RejectsBadInputs) {
  DeviceCloud cloud;
  cloud.points = compute::Buffer<Point4f>(context(), 10);
  EXPECT_THROW(geometry::subsample(context(), cloud, 0), Error);
  cloud.colors = compute::Buffer<std::uint32_t>(context(), 9);
  EXPECT_THROW(geometry::subsample(context(), cloud, 2), Error);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(SubsampleTest);

}  // namespace
}  // namespace kartograf
