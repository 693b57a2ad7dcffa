// Projective association on every backend against an all-double reference of the documented
// rules (registration/projective_association.hpp). Stated tolerance: every entry equal, except
// where the reference itself is within 1e-3 pixel of a rounding boundary, within 3 um of the
// distance gate or of another candidate, or 1e-5 of the normal gate's cosine (the association
// works in float); those borderline entries are counted and must be rare (< 0.1%).
#include <cmath>
#include <numbers>

#include "icp_test_scene.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/projective_association.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using registration::AssociationParams;
using registration::CloudView;
using registration::kNoMatch;
using registration::kNotSelected;
using testing::BackendTest;

struct Reference {
  std::int32_t index = kNoMatch;
  bool borderline = false;
};

// The rules in double; flags cases the float arithmetic may resolve either way.
Reference reference_entry(std::size_t i, const PointImage& source,
                          const NormalImage& source_normals, const PointImage& target,
                          const NormalImage& target_normals, const PinholeIntrinsics& k,
                          const Eigen::Isometry3d& pose, const AssociationParams& params) {
  Reference result;
  const int width = source.width();
  if (!registration::is_selected(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(width),
                                 static_cast<std::uint32_t>(params.subsample))) {
    return {kNotSelected, false};
  }
  const Point4f& p = source.pixels()[i];
  if (!is_valid(p)) return result;
  const Eigen::Vector3d moved = pose * p.head<3>().cast<double>();
  if (moved.z() <= 0) return result;
  const double u = k.fx * moved.x() / moved.z() + k.cx, v = k.fy * moved.y() / moved.z() + k.cy;
  const auto near_half = [](double x) { return std::fabs(x - std::floor(x) - 0.5) < 1e-3; };
  result.borderline = near_half(u) || near_half(v);
  const long pu = std::lround(std::floor(u + 0.5)), pv = std::lround(std::floor(v + 0.5));
  const bool gate = params.max_normal_angle_deg < 180;
  const double min_cos = std::cos(params.max_normal_angle_deg * std::numbers::pi / 180);
  const Eigen::Vector3d n = pose.linear() * source_normals.pixels()[i].head<3>().cast<double>();
  if (gate && !is_valid(source_normals.pixels()[i])) return result;
  double best = params.max_distance * params.max_distance;
  for (long y = pv - params.search_radius; y <= pv + params.search_radius; ++y) {
    for (long x = pu - params.search_radius; x <= pu + params.search_radius; ++x) {
      if (x < 0 || y < 0 || x >= k.width || y >= k.height) continue;
      const Point4f& q = target(static_cast<int>(x), static_cast<int>(y));
      if (!is_valid(q)) continue;
      const double distance_sq = (moved - q.head<3>().cast<double>()).squaredNorm();
      // Float coordinates of metres resolve distances to ~1 um.
      if (std::fabs(std::sqrt(distance_sq) - std::sqrt(best)) < 3e-6) result.borderline = true;
      if (!(distance_sq <= best) || (result.index >= 0 && distance_sq == best)) continue;
      if (gate) {
        const Point4f& nq = target_normals(static_cast<int>(x), static_cast<int>(y));
        if (!is_valid(nq)) continue;
        const double cosine = n.dot(nq.head<3>().cast<double>());
        if (std::fabs(cosine - min_cos) < 1e-5) result.borderline = true;
        if (!(cosine >= min_cos)) continue;
      }
      result.index = static_cast<std::int32_t>(y * k.width + x);
      best = distance_sq;
    }
  }
  return result;
}

class ProjectiveAssociationTest : public BackendTest {
 protected:
  // Associates frame `source` (moved by `motion`) with `target`; returns the worst mismatches.
  void check(const registration::FramePyramid& source, const registration::FramePyramid& target,
             const Eigen::Isometry3d& pose, const AssociationParams& params,
             const std::string& what) {
    registration::ProjectiveAssociation finder(context());
    registration::CorrespondenceBuffers out;
    finder.find(source.level(0).view(), target.level(0).view(), pose, params, out);
    ASSERT_EQ(out.target_index.size(), source.level(0).points.size());
    EXPECT_TRUE(out.weights.empty());
    const std::vector<std::int32_t> actual = out.target_index.to_vector();
    const PointImage sp = source.level(0).points.to_image(), tp = target.level(0).points.to_image();
    const NormalImage sn = source.level(0).normals.to_image(),
                      tn = target.level(0).normals.to_image();
    std::size_t borderline = 0, matched = 0, selected = 0;
    for (std::size_t i = 0; i < actual.size(); ++i) {
      const Reference expected =
          reference_entry(i, sp, sn, tp, tn, target.level(0).camera, pose, params);
      if (expected.index != kNotSelected) ++selected;
      if (expected.index >= 0) ++matched;
      if (actual[i] == expected.index) continue;
      ASSERT_TRUE(expected.borderline)
          << what << ": entry " << i << " is " << actual[i] << ", expected " << expected.index;
      ++borderline;
    }
    EXPECT_LT(borderline, actual.size() / 1000 + 1) << what;
    EXPECT_GT(matched, selected / 2) << what;  // the case is not vacuous
    RecordProperty(what + "_borderline_entries", static_cast<int>(borderline));
  }
};

TEST_P(ProjectiveAssociationTest, MatchesReference) {
  const PinholeIntrinsics camera = testing::qvga_camera();
  const Eigen::Isometry3d motion = Eigen::Translation3d(0.03, -0.01, 0.02) *
                                   Eigen::AngleAxisd(0.03, Eigen::Vector3d(1, 2, 0.5).normalized());
  const Eigen::Isometry3d source_pose = testing::reference_camera();
  const auto source = registration::make_frame_pyramid(
      context(), camera, testing::render(testing::corner_scene(), camera, source_pose));
  const auto target = registration::make_frame_pyramid(
      context(), camera, testing::render(testing::corner_scene(), camera, source_pose * motion));
  // Near the truth (pose = motion^-1) and off it, with and without gates, window and subsampling.
  const Eigen::Isometry3d off = Eigen::Translation3d(0.01, 0.0, -0.01) * motion.inverse();
  check(source, target, motion.inverse(), {0.05, 30, 1, 0}, "truth");
  check(source, target, off, {0.03, 20, 1, 0}, "off_gated");
  check(source, target, off, {0.1, 180, 3, 0}, "subsampled_no_normal_gate");
  check(source, target, off, {0.05, 30, 1, 2}, "window_5x5");
  check(source, target, off, {0.05, 180, 7, 1}, "window_3x3_subsampled");
}

TEST_P(ProjectiveAssociationTest, SelectsOneInK) {
  for (std::uint32_t k : {1u, 2u, 10u}) {
    std::size_t selected = 0;
    for (std::uint32_t i = 0; i < 640 * 480; ++i) selected += registration::is_selected(i, 640, k);
    EXPECT_EQ(selected, 640u * 480u / k);
  }
  // A diagonal lattice on a width divisible by k, not every k-th column.
  EXPECT_TRUE(registration::is_selected(0, 640, 10));
  EXPECT_TRUE(registration::is_selected(640 + 9, 640, 10));
  EXPECT_FALSE(registration::is_selected(640, 640, 10));
  EXPECT_TRUE(registration::is_selected(20, 0, 10));  // unorganized: every k-th point
}

TEST_P(ProjectiveAssociationTest, RejectsBadInput) {
  const PinholeIntrinsics camera = testing::qvga_camera();
  const auto frame = registration::make_frame_pyramid(
      context(), camera,
      testing::render(testing::plane_scene(), camera, Eigen::Isometry3d::Identity()));
  registration::ProjectiveAssociation finder(context());
  registration::CorrespondenceBuffers out;
  CloudView source = frame.level(0).view(), target = frame.level(0).view();
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  EXPECT_NO_THROW(finder.find(source, target, pose, {}, out));
  CloudView unorganized = target;
  unorganized.camera.reset();
  EXPECT_THROW(finder.find(source, unorganized, pose, {}, out), Error);
  CloudView wrong_size = target;
  wrong_size.camera = frame.level(1).camera;
  EXPECT_THROW(finder.find(source, wrong_size, pose, {}, out), Error);
  CloudView no_normals = source;
  no_normals.normals = nullptr;
  EXPECT_THROW(finder.find(no_normals, target, pose, {}, out), Error);
  EXPECT_NO_THROW(finder.find(no_normals, target, pose, {0.1, 180, 1, 0}, out));  // gate off
  EXPECT_THROW(finder.find(source, target, pose, {0.1, 30, 0, 0}, out), Error);
  EXPECT_THROW(finder.find(source, target, pose, {-1, 30, 1, 0}, out), Error);
  EXPECT_THROW(finder.find(source, target, pose, {0.1, 30, 1, -1}, out), Error);
  Eigen::Isometry3d bad = pose;
  bad.translation().x() = std::nan("");
  EXPECT_THROW(finder.find(source, target, bad, {}, out), Error);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(ProjectiveAssociationTest);

}  // namespace
}  // namespace kartograf
