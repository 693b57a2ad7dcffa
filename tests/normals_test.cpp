// Organized normals on every backend vs a double-precision reference of the same rules.
// Stated tolerance: validity masks identical; max |component error| <= 1e-5 (float tangents,
// 2-ulp inverse square roots); where the surface is seen exactly edge-on (|n . p| / |p| < 1e-5)
// the orientation is ill-defined and the normal is compared up to sign.
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using testing::BackendTest;

// The rules of geometry/normals.hpp in double (the depth-jump test is defined in float).
NormalImage reference_normals(const PointImage& points, float max_depth_jump) {
  const int w = points.width(), h = points.height();
  NormalImage normals(w, h, invalid_point());
  auto usable = [&](int x, int y, const Point4f& centre) {
    if (x < 0 || y < 0 || x >= w || y >= h) return false;
    const Point4f& n = points(x, y);
    return is_valid(n) && std::fabs(n.z() - centre.z()) <= max_depth_jump * centre.z();
  };
  auto tangent = [&](int x0, int y0, int x1, int y1, const Point4f& c, Eigen::Vector3d& t) {
    const bool before = usable(x0, y0, c), after = usable(x1, y1, c);
    const Eigen::Vector3d centre = c.head<3>().cast<double>();
    if (before && after) {
      t = points(x1, y1).head<3>().cast<double>() - points(x0, y0).head<3>().cast<double>();
    } else if (after) {
      t = points(x1, y1).head<3>().cast<double>() - centre;
    } else if (before) {
      t = centre - points(x0, y0).head<3>().cast<double>();
    } else {
      return false;
    }
    return true;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Point4f& c = points(x, y);
      Eigen::Vector3d tx, ty;
      if (!is_valid(c) || !tangent(x - 1, y, x + 1, y, c, tx) || !tangent(x, y - 1, x, y + 1, c, ty)) continue;
      Eigen::Vector3d n = tx.cross(ty);
      if (!(n.squaredNorm() > 1e-12 * tx.squaredNorm() * ty.squaredNorm())) continue;
      n.normalize();
      if (n.dot(c.head<3>().cast<double>()) > 0) n = -n;
      normals(x, y) << n.cast<float>(), 0.0f;
    }
  }
  return normals;
}

struct Comparison {
  double max_error = 0;
  std::size_t valid = 0;
  std::size_t mask_mismatches = 0;
};

Comparison compare(const PointImage& points, const NormalImage& expected, const NormalImage& actual) {
  Comparison result;
  for (int y = 0; y < points.height(); ++y) {
    for (int x = 0; x < points.width(); ++x) {
      const Point4f& e = expected(x, y);
      const Point4f& a = actual(x, y);
      if (is_valid(e) != is_valid(a)) {
        ++result.mask_mismatches;
        continue;
      }
      if (!is_valid(e)) continue;
      ++result.valid;
      double error = (e - a).cwiseAbs().maxCoeff();
      const Eigen::Vector3f view = points(x, y).head<3>().normalized();
      if (std::fabs(e.head<3>().dot(view)) < 1e-5f) {
        error = std::min(error, static_cast<double>((e + a).head<3>().cwiseAbs().maxCoeff()));
      }
      result.max_error = std::max(result.max_error, error);
    }
  }
  return result;
}

// A wavy, slanted surface with holes and a box in front of it (depth discontinuities).
DepthImage synthetic_depth(int width, int height, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> phase(0, 6.28);
  const double px = phase(rng), py = phase(rng);
  std::uniform_int_distribution<int> hole(0, 49);
  DepthImage depth(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      double z = 2.0 + 0.8 * u / width + 0.15 * std::sin(0.03 * u + px) * std::cos(0.02 * v + py);
      if (u > width / 3 && u < width / 2 && v > height / 3 && v < 2 * height / 3) z -= 0.9;
      depth(u, v) = hole(rng) == 0 ? 0 : static_cast<std::uint16_t>(std::lround(z * 1000));
    }
  }
  return depth;
}

class NormalsTest : public BackendTest {};

TEST_P(NormalsTest, MatchesReferenceOnSyntheticSurfaces) {
  const compute::Context cpu = compute::Context::cpu();
  for (auto [width, height] : {std::pair{640, 480}, std::pair{1280, 720}, std::pair{97, 61}}) {
    const PinholeIntrinsics k{width, height, 525, 525, width / 2.0 - 0.5, height / 2.0 - 0.5};
    const PointImage points = geometry::backproject(cpu, synthetic_depth(width, height, rng), k);
    const NormalImage normals = geometry::estimate_normals(context(), points);
    const Comparison c = compare(points, reference_normals(points, 0.05f), normals);
    EXPECT_EQ(c.mask_mismatches, 0u) << width << "x" << height;
    EXPECT_GT(c.valid, points.size() / 2);
    EXPECT_LE(c.max_error, 1e-5) << width << "x" << height;
  }
}

TEST_P(NormalsTest, MatchesReferenceOnSevenScenesFrames) {
  const compute::Context cpu = compute::Context::cpu();
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  for (const char* frame : {"frame-000000", "frame-000299"}) {
    const DepthImage depth = testing::read_depth(frames / (std::string(frame) + ".depth.png"));
    const PointImage points = geometry::backproject(cpu, depth, PinholeIntrinsics::kinect_7scenes());
    const NormalImage normals = geometry::estimate_normals(context(), points);
    const Comparison c = compare(points, reference_normals(points, 0.05f), normals);
    EXPECT_EQ(c.mask_mismatches, 0u) << frame;
    EXPECT_GT(c.valid, 150000u) << frame;
    EXPECT_LE(c.max_error, 1e-5) << frame;
    RecordProperty(std::string("max_abs_error_") + frame, testing::scientific(c.max_error));
  }
}

TEST_P(NormalsTest, PlaneFacingCameraAndDepthEdges) {
  // A fronto-parallel wall at 2 m with a step to 1 m in its right half: normals are (0, 0, -1)
  // everywhere valid, and the columns beside the step still get one-sided normals.
  const int width = 40, height = 30;
  DepthImage depth(width, height, 2000);
  for (int v = 0; v < height; ++v) {
    for (int u = width / 2; u < width; ++u) depth(u, v) = 1000;
  }
  const compute::Context cpu = compute::Context::cpu();
  const PointImage points = geometry::backproject(cpu, depth, PinholeIntrinsics{width, height, 100, 100, 20, 15});
  const NormalImage normals = geometry::estimate_normals(context(), points);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      ASSERT_TRUE(is_valid(normals(u, v))) << u << "," << v;
      EXPECT_NEAR(normals(u, v).z(), -1.0f, 1e-6f) << u << "," << v;
    }
  }
  depth(5, 5) = 0;  // a hole: its neighbours fall back to one-sided differences
  const NormalImage with_hole = geometry::estimate_normals(context(), geometry::backproject(cpu, depth, PinholeIntrinsics{width, height, 100, 100, 20, 15}));
  EXPECT_FALSE(is_valid(with_hole(5, 5)));
  EXPECT_TRUE(is_valid(with_hole(4, 5)));
  EXPECT_TRUE(is_valid(with_hole(5, 4)));
}

TEST_P(NormalsTest, RejectsBadParameters) {
  const PointImage points(4, 4, invalid_point());
  EXPECT_THROW(geometry::estimate_normals(context(), points, geometry::NormalParams{-1.0f}), Error);
  EXPECT_THROW(geometry::estimate_normals(context(), points, geometry::NormalParams{NAN}), Error);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(NormalsTest);

}  // namespace
}  // namespace kartograf
