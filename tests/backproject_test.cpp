// Depth back-projection on every backend vs an all-double reference.
// Stated tolerance: max |error| <= 1e-6 m for points within 8 m; validity masks identical.
#include <cmath>
#include <string>

#include "kartograf/geometry/backproject.hpp"
#include "real_data.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using geometry::DepthRange;
using testing::BackendTest;

struct Comparison {
  double max_error = 0;
  std::size_t valid = 0;
  std::size_t mask_mismatches = 0;
};

Comparison compare_with_reference(const DepthImage& depth, const PinholeIntrinsics& k,
                                  const DepthRange& range, const PointImage& points) {
  Comparison result;
  for (int v = 0; v < depth.height(); ++v) {
    for (int u = 0; u < depth.width(); ++u) {
      const double d = depth(u, v);
      const double z = d / range.units_per_metre;
      const bool valid = d != 0 && z >= range.min_metres && z <= range.max_metres;
      const Point4f& p = points(u, v);
      if (valid != is_valid(p) || (!valid && !p.array().isNaN().all())) {
        ++result.mask_mismatches;
        continue;
      }
      if (!valid) continue;
      ++result.valid;
      const double x = (u - k.cx) * z / k.fx;
      const double y = (v - k.cy) * z / k.fy;
      result.max_error = std::max({result.max_error, std::fabs(p.x() - x), std::fabs(p.y() - y),
                                   std::fabs(p.z() - z), std::fabs(p.w() - 1.0)});
    }
  }
  return result;
}

class BackprojectTest : public BackendTest {};

TEST_P(BackprojectTest, MatchesDoubleReferenceOnRandomDepth) {
  // Odd sizes exercise partial work-groups and the packing of 16-bit depth into 32-bit words.
  for (auto [width, height] : {std::pair{640, 480}, std::pair{1280, 720}, std::pair{333, 211}}) {
    std::uniform_real_distribution<double> focal(400, 700), offset(-20.5, 20.5);
    PinholeIntrinsics k{width, height, focal(rng), focal(rng), width / 2.0 + offset(rng),
                        height / 2.0 + offset(rng)};
    const DepthRange range{1000.0, 0.3, 7.9};
    DepthImage depth(width, height);
    std::uniform_int_distribution<int> raw(0, 8200), hole(0, 9);
    for (auto& d : depth.pixels()) d = hole(rng) == 0 ? 0 : static_cast<std::uint16_t>(raw(rng));

    const PointImage points = geometry::backproject(context(), depth, k, range);
    const Comparison c = compare_with_reference(depth, k, range, points);
    EXPECT_EQ(c.mask_mismatches, 0u) << width << "x" << height;
    EXPECT_GT(c.valid, depth.size() / 2);
    EXPECT_LE(c.max_error, 1e-6) << width << "x" << height;
    RecordProperty("max_abs_error_m_" + std::to_string(width), testing::scientific(c.max_error));
  }
}

TEST_P(BackprojectTest, TumDepthScaleAndRangeLimits) {
  const PinholeIntrinsics k{64, 48, 517.3, 516.5, 31.1, 23.7};
  const DepthRange range{5000.0, 0.5, 4.0};  // TUM: 5000 units per metre
  DepthImage depth(64, 48);
  std::uniform_int_distribution<int> raw(0, 25000);
  for (auto& d : depth.pixels()) d = static_cast<std::uint16_t>(raw(rng));
  depth(0, 0) = 2500;   // exactly min: valid
  depth(1, 0) = 2499;   // just below: invalid
  depth(2, 0) = 20000;  // exactly max: valid
  depth(3, 0) = 20001;  // just above: invalid
  const PointImage points = geometry::backproject(context(), depth, k, range);
  EXPECT_TRUE(is_valid(points(0, 0)));
  EXPECT_FALSE(is_valid(points(1, 0)));
  EXPECT_TRUE(is_valid(points(2, 0)));
  EXPECT_FALSE(is_valid(points(3, 0)));
  const Comparison c = compare_with_reference(depth, k, range, points);
  EXPECT_EQ(c.mask_mismatches, 0u);
  EXPECT_LE(c.max_error, 1e-6);
}

TEST_P(BackprojectTest, MatchesDoubleReferenceOnSevenScenesFrames) {
  const auto frames = testing::data_dir() / "7scenes_redkitchen" / "frames";
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_7scenes();
  const DepthRange range{1000.0, 0.1, 8.0};
  const geometry::DepthBackprojector projector(context(), k, range);
  compute::DeviceImage<Point4f> points(context(), k.width, k.height);
  for (const char* frame : {"frame-000000", "frame-000150", "frame-000299"}) {
    const DepthImage depth = testing::read_depth(frames / (std::string(frame) + ".depth.png"));
    projector.run(compute::DeviceImage<std::uint16_t>::from_host(context(), depth), points);
    const Comparison c = compare_with_reference(depth, k, range, points.to_image());
    EXPECT_EQ(c.mask_mismatches, 0u) << frame;
    EXPECT_GT(c.valid, 200000u) << frame;
    EXPECT_LE(c.max_error, 1e-6) << frame;
    RecordProperty(std::string("max_abs_error_m_") + frame, testing::scientific(c.max_error));
  }
}

TEST_P(BackprojectTest, RejectsBadInput) {
  const PinholeIntrinsics k{64, 48, 500, 500, 32, 24};
  EXPECT_THROW(geometry::DepthBackprojector(context(), k, DepthRange{0.0, 0.1, 5}), Error);
  EXPECT_THROW(geometry::DepthBackprojector(context(), k, DepthRange{1000, 5, 1}), Error);
  EXPECT_THROW(geometry::DepthBackprojector(context(), k, DepthRange{NAN, 0.1, 5}), Error);
  EXPECT_THROW(geometry::DepthBackprojector(context(), PinholeIntrinsics{64, 48, 0, 500, 32, 24},
                                            DepthRange{}),
               Error);
  const DepthImage wrong_size(32, 24, 1000);
  EXPECT_ERROR_MENTIONS(geometry::backproject(context(), wrong_size, k), "32x24");
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(BackprojectTest);

}  // namespace
}  // namespace kartograf
