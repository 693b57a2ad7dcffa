// Frame pyramids on every backend against a reference written from the documented rule
// (registration/frame_pyramid.hpp). Stated tolerance: identical validity masks and colours,
// coordinates within 1e-6 m (the rule fixes the float operations; only rounding of the driver's
// arithmetic may differ), normals of each level identical to estimate_normals on that level.
#include <algorithm>
#include <cmath>

#include "icp_test_scene.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using registration::FramePyramid;
using testing::BackendTest;

// The rule, evaluated independently: foreground points of each 2x2 block, averaged in double.
struct Coarse {
  PointImage points;
  Image<std::uint32_t> colors;
};

Coarse reference_downsample(const PointImage& fine, const Image<std::uint32_t>& fine_colors,
                            float max_depth_jump) {
  Coarse coarse{PointImage(fine.width() / 2, fine.height() / 2, invalid_point()),
                Image<std::uint32_t>(fine.width() / 2, fine.height() / 2, 0u)};
  for (int y = 0; y < coarse.points.height(); ++y) {
    for (int x = 0; x < coarse.points.width(); ++x) {
      std::vector<std::pair<int, int>> valid;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          if (is_valid(fine(2 * x + dx, 2 * y + dy))) valid.emplace_back(2 * x + dx, 2 * y + dy);
        }
      }
      if (valid.empty()) continue;
      float z_min = fine(valid[0].first, valid[0].second).z();
      for (const auto& [u, v] : valid) z_min = std::min(z_min, fine(u, v).z());
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int channel[3] = {0, 0, 0};
      int count = 0;
      for (const auto& [u, v] : valid) {
        if (!(fine(u, v).z() - z_min <= max_depth_jump * z_min)) continue;
        sum += fine(u, v).head<3>().cast<double>();
        for (int c = 0; c < 3; ++c) channel[c] += unpack_rgb(fine_colors(u, v))[c];
        ++count;
      }
      const Eigen::Vector3d mean = sum / count;
      coarse.points(x, y) = Point4f(mean.x(), mean.y(), mean.z(), 1.0f);
      Rgb8 color;
      for (int c = 0; c < 3; ++c) {
        color[c] = static_cast<std::uint8_t>(std::floor(channel[c] / double(count) + 0.5));
      }
      coarse.colors(x, y) = pack_rgb(color);
    }
  }
  return coarse;
}

// A scene with depth edges (boxes in a room), some holes, and random colours.
struct Frame {
  PointImage points;
  Image<std::uint32_t> colors;
};

Frame test_frame(const PinholeIntrinsics& camera, std::mt19937_64& rng) {
  Frame frame{testing::render(testing::corner_scene(), camera, testing::reference_camera()),
              Image<std::uint32_t>(camera.width, camera.height)};
  std::uniform_int_distribution<std::uint32_t> color(0, 0xffffff);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      frame.colors(u, v) = color(rng);
      if (unit(rng) < 0.05) frame.points(u, v) = invalid_point();
    }
  }
  return frame;
}

class FramePyramidTest : public BackendTest {};

TEST_P(FramePyramidTest, LevelsFollowTheRule) {
  // Odd sizes: the last column and row of an odd level have no coarse pixel.
  const PinholeIntrinsics camera{321, 243, 262.5, 262.5, 160.0, 121.0};
  const Frame frame = test_frame(camera, rng);
  registration::PyramidParams params;
  params.levels = 4;
  const FramePyramid pyramid =
      registration::make_frame_pyramid(context(), camera, frame.points, &frame.colors, params);
  ASSERT_EQ(pyramid.level_count(), 4);
  const compute::Context cpu = compute::Context::cpu();
  PointImage fine = frame.points;
  Image<std::uint32_t> fine_colors = frame.colors;
  double worst = 0;
  for (int level = 0; level < 4; ++level) {
    const registration::PyramidLevel& actual = pyramid.level(level);
    if (level > 0) {
      const Coarse expected = reference_downsample(fine, fine_colors, params.max_depth_jump);
      const PointImage points = actual.points.to_image();
      const Image<std::uint32_t> colors = actual.colors.to_image();
      ASSERT_EQ(points.width(), expected.points.width());
      ASSERT_EQ(points.height(), expected.points.height());
      for (int v = 0; v < points.height(); ++v) {
        for (int u = 0; u < points.width(); ++u) {
          ASSERT_EQ(is_valid(points(u, v)), is_valid(expected.points(u, v)))
              << level << " " << u << "," << v;
          if (!is_valid(points(u, v))) continue;
          worst =
              std::max(worst, double((points(u, v) - expected.points(u, v)).cwiseAbs().maxCoeff()));
          ASSERT_EQ(colors(u, v), expected.colors(u, v)) << level << " " << u << "," << v;
        }
      }
      fine = points;
      fine_colors = colors;
    }
    // Each level's normals are estimate_normals of its points.
    const NormalImage normals = actual.normals.to_image();
    const NormalImage expected_normals = geometry::estimate_normals(cpu, actual.points.to_image());
    for (std::size_t i = 0; i < normals.size(); ++i) {
      ASSERT_EQ(is_valid(normals.pixels()[i]), is_valid(expected_normals.pixels()[i]));
      if (is_valid(normals.pixels()[i])) {
        EXPECT_LE((normals.pixels()[i] - expected_normals.pixels()[i]).cwiseAbs().maxCoeff(), 1e-5);
      }
    }
  }
  EXPECT_LE(worst, 1e-6);
  RecordProperty("max_coordinate_error_m", testing::scientific(worst));
}

TEST_P(FramePyramidTest, BlocksOnADepthEdgeTakeTheForeground) {
  const PinholeIntrinsics camera{16, 16, 20.0, 20.0, 7.5, 7.5};
  PointImage points(16, 16);
  for (int v = 0; v < 16; ++v) {
    for (int u = 0; u < 16; ++u) {
      const float z = u < 5 ? 1.0f : 3.0f;  // an edge through the blocks of columns 4-5
      points(u, v) = Point4f((u - 7.5f) / 20.0f * z, (v - 7.5f) / 20.0f * z, z, 1.0f);
    }
  }
  registration::PyramidParams params;
  params.levels = 2;
  const FramePyramid pyramid =
      registration::make_frame_pyramid(context(), camera, points, nullptr, params);
  const PointImage coarse = pyramid.level(1).points.to_image();
  for (int v = 0; v < 8; ++v) {
    EXPECT_FLOAT_EQ(coarse(1, v).z(), 1.0f);
    EXPECT_FLOAT_EQ(coarse(2, v).z(), 1.0f);  // columns 4 (z = 1) and 5 (z = 3): foreground only
    EXPECT_FLOAT_EQ(coarse(2, v).x(), (4 - 7.5f) / 20.0f);
    EXPECT_FLOAT_EQ(coarse(3, v).z(), 3.0f);
  }
  EXPECT_FALSE(pyramid.level(1).colors.size());  // made without colours
}

TEST_P(FramePyramidTest, PlanesStayPlanesAndProjectWhereTheyAre) {
  // A slanted wall: every coarse point lies on it, and projects with the level's camera to
  // within a pixel of where it was averaged from.
  const PinholeIntrinsics camera = testing::qvga_camera();
  testing::Scene wall;
  wall.planes.push_back({Eigen::Vector3d(0.3, -0.2, 1.0).normalized(), 2.0});
  const PointImage points = testing::render(wall, camera, Eigen::Isometry3d::Identity());
  const FramePyramid pyramid = registration::make_frame_pyramid(context(), camera, points);
  const Eigen::Vector3d normal = wall.planes[0].normal;
  for (int level = 1; level < pyramid.level_count(); ++level) {
    const PinholeIntrinsics& k = pyramid.level(level).camera;
    const PointImage coarse = pyramid.level(level).points.to_image();
    double worst_plane = 0, worst_pixel = 0;
    for (int v = 0; v < coarse.height(); ++v) {
      for (int u = 0; u < coarse.width(); ++u) {
        const Eigen::Vector3d p = coarse(u, v).head<3>().cast<double>();
        worst_plane = std::max(worst_plane, std::fabs(normal.dot(p) - 2.0));
        worst_pixel = std::max({worst_pixel, std::fabs(k.fx * p.x() / p.z() + k.cx - u),
                                std::fabs(k.fy * p.y() / p.z() + k.cy - v)});
      }
    }
    EXPECT_LT(worst_plane, 1e-5) << level;
    EXPECT_LT(worst_pixel, 0.05) << level;
  }
}

TEST_P(FramePyramidTest, BuildsFromDepthAndRejectsBadInput) {
  const PinholeIntrinsics camera = testing::qvga_camera();
  DepthImage depth(camera.width, camera.height, 1500);
  const geometry::DepthBackprojector projector(context(), camera, geometry::DepthRange{});
  FramePyramid pyramid(context(), camera);
  pyramid.build(projector, compute::DeviceImage<std::uint16_t>::from_host(context(), depth));
  const PointImage coarsest = pyramid.level(2).points.to_image();
  EXPECT_FLOAT_EQ(coarsest(10, 10).z(), 1.5f);
  EXPECT_EQ(pyramid.level(2).camera.width, 80);
  EXPECT_DOUBLE_EQ(pyramid.level(2).camera.cx, (((159.5 - 0.5) / 2) - 0.5) / 2);

  registration::PyramidParams params;
  params.levels = 0;
  EXPECT_THROW(FramePyramid(context(), camera, params), Error);
  params.levels = 6;  // 320x240 -> ... -> 10x7: under 8 pixels
  EXPECT_THROW(FramePyramid(context(), camera, params), Error);
  EXPECT_THROW(pyramid.base_colors(), Error);
  const geometry::DepthBackprojector other(context(), testing::vga_camera(),
                                           geometry::DepthRange{});
  EXPECT_THROW(pyramid.build(other, compute::DeviceImage<std::uint16_t>(context(), 640, 480)),
               Error);
  EXPECT_THROW(registration::make_frame_pyramid(context(), camera, PointImage(10, 10)), Error);
}

// Levels finer than first_normals_level carry no normals; the others equal a full pyramid's.
TEST_P(FramePyramidTest, NormalsOnlyFromTheFirstNormalsLevel) {
  const PinholeIntrinsics camera = testing::qvga_camera();
  const PointImage points =
      testing::render(testing::corner_scene(), camera, testing::reference_camera());
  registration::PyramidParams params;
  params.first_normals_level = 1;
  const FramePyramid partial =
      registration::make_frame_pyramid(context(), camera, points, nullptr, params);
  const FramePyramid full = registration::make_frame_pyramid(context(), camera, points);
  EXPECT_EQ(partial.level(0).normals.size(), 0u);
  EXPECT_EQ(partial.level(0).view().normals, nullptr);
  for (int level = 1; level < full.level_count(); ++level) {
    const PointImage a = partial.level(level).normals.to_image();
    const PointImage b = full.level(level).normals.to_image();
    ASSERT_EQ(a.pixels().size(), b.pixels().size());
    std::size_t valid = 0;
    for (std::size_t i = 0; i < a.pixels().size(); ++i) {
      if (std::isnan(b.pixels()[i].x())) continue;
      ++valid;
      EXPECT_EQ(a.pixels()[i], b.pixels()[i]) << "level " << level << " pixel " << i;
    }
    EXPECT_GT(valid, a.pixels().size() / 2) << "level " << level;
  }
  params.first_normals_level = 3;  // the default 3 levels: 0..2
  EXPECT_THROW(FramePyramid(context(), camera, params), Error);
  params.first_normals_level = -1;
  EXPECT_THROW(FramePyramid(context(), camera, params), Error);
}

TEST(PackedRgb, RoundTrips) {
  const Rgb8 color{12, 200, 255};
  EXPECT_EQ(pack_rgb(color), 12u | 200u << 8 | 255u << 16);
  EXPECT_EQ(unpack_rgb(pack_rgb(color)), color);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(FramePyramidTest);

}  // namespace
}  // namespace kartograf
