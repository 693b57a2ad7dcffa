// The ICP engine on every backend, on analytic scenes ray cast from known poses (noise-free):
// known-motion recovery (rotation < 0.05 deg, translation < 1 mm) for both metrics with and
// without the pyramid, device vs CPU agreement, degeneracy, robust kernels, fitness and RMSE.
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>

#include "icp_test_scene.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using registration::ErrorMetric;
using registration::FramePyramid;
using registration::IcpEngine;
using registration::IcpLevelParams;
using registration::IcpParams;
using registration::IcpResult;
using testing::BackendTest;

// Two frames of one scene: the target camera is the source camera moved by `motion`, so the
// true source-to-target transform is motion^-1.
struct FramePair {
  PinholeIntrinsics camera;
  PointImage source, target;
  Eigen::Isometry3d truth;
};

Eigen::Isometry3d camera_motion(double angle_deg, const Eigen::Vector3d& axis,
                                const Eigen::Vector3d& translation) {
  return Eigen::Translation3d(translation) *
         Eigen::AngleAxisd(angle_deg * std::numbers::pi / 180.0, axis.normalized());
}

FramePair make_pair(const testing::Scene& source_scene, const testing::Scene& target_scene,
                    const Eigen::Isometry3d& motion,
                    const PinholeIntrinsics& camera = testing::qvga_camera()) {
  const Eigen::Isometry3d source_pose = testing::reference_camera();
  return {camera, testing::render(source_scene, camera, source_pose),
          testing::render(target_scene, camera, source_pose * motion), motion.inverse()};
}

// A typical frame-to-frame motion at walking speed, a little large for 30 Hz.
const Eigen::Isometry3d kMotion = camera_motion(3.0, {1, 2, 0.5}, {0.04, -0.02, 0.03});

IcpParams point_to_plane_params(int levels) {
  IcpParams params;
  params.levels = {{20, 1, 0.03, 0.01}, {15, 1, 0.08, 0.03}, {15, 1, 0.15, 0.06}};
  params.levels.resize(static_cast<std::size_t>(levels));
  params.convergence = {1e-6, 1e-6};
  return params;
}

// Point-to-point converges linearly (pairs on one plane pin the motion along it), so it gets
// more iterations, the closest point within a pixel or two, and 1 in 4 points at full
// resolution. Each level must bring the estimate within ~1 pixel of the next: with fewer coarse
// iterations the full-resolution window misses the closest points and the estimate drifts off.
IcpParams point_to_point_params(int levels) {
  IcpParams params;
  params.metric = ErrorMetric::point_to_point;
  params.levels = {{60, 8, 0.03, 0.01, 1}, {30, 1, 0.08, 0.03, 2}, {30, 1, 0.15, 0.06, 2}};
  params.levels.resize(static_cast<std::size_t>(levels));
  params.convergence = {1e-5, 1e-5};
  return params;
}

class IcpEngineTest : public BackendTest {
 protected:
  IcpResult align(const FramePair& pair, const IcpParams& params,
                  const Eigen::Isometry3d& initial = Eigen::Isometry3d::Identity()) {
    return align_on(context(), pair, params, initial);
  }
  static IcpResult align_on(const compute::Context& context, const FramePair& pair,
                            const IcpParams& params, const Eigen::Isometry3d& initial) {
    registration::PyramidParams pyramid;
    pyramid.levels = static_cast<int>(params.levels.size());
    const FramePyramid source =
        registration::make_frame_pyramid(context, pair.camera, pair.source, nullptr, pyramid);
    const FramePyramid target =
        registration::make_frame_pyramid(context, pair.camera, pair.target, nullptr, pyramid);
    IcpEngine engine(context, params);
    return engine.align(source, target, initial);
  }
  void expect_recovered(const IcpResult& result, const FramePair& pair, const std::string& what) {
    const double rotation = testing::rotation_error_deg(result.source_to_target, pair.truth);
    const double translation = testing::translation_error(result.source_to_target, pair.truth);
    EXPECT_LT(rotation, 0.05) << what;
    EXPECT_LT(translation, 0.001) << what;
    EXPECT_TRUE(result.converged) << what;
    RecordProperty(what + "_rotation_error_deg", testing::scientific(rotation));
    RecordProperty(what + "_translation_error_m", testing::scientific(translation));
    RecordProperty(what + "_iterations", result.iterations);
    std::string per_level;
    for (int n : result.level_iterations) per_level += std::to_string(n) + " ";
    RecordProperty(what + "_level_iterations", per_level);
  }
};

TEST_P(IcpEngineTest, PointToPlaneRecoversKnownMotion) {
  const FramePair pair = make_pair(testing::corner_scene(), testing::corner_scene(), kMotion);
  const IcpResult pyramid = align(pair, point_to_plane_params(3));
  expect_recovered(pyramid, pair, "pyramid");
  EXPECT_EQ(pyramid.level_iterations.size(), 3u);
  EXPECT_GT(pyramid.fitness, 0.85);  // the motion takes ~10% of the view out of the target's
  EXPECT_FALSE(pyramid.degeneracy.degenerate);
  // One level needs a gate wider than the initial error: a tight gate keeps only the surfaces
  // that already agree, and the first step slides along them.
  IcpParams single = point_to_plane_params(1);
  single.levels[0] = {40, 1, 0.15, 0.05};
  expect_recovered(align(pair, single), pair, "single_level");
}

// Full resolution: point-to-point's fixed point is biased by the surface sampling (nearest
// samples on grazing surfaces): ~0.06 deg / 3 mm at 320x240, half that at 640x480.
TEST_P(IcpEngineTest, PointToPointRecoversKnownMotionWithPyramid) {
  const FramePair pair =
      make_pair(testing::corner_scene(), testing::corner_scene(), kMotion, testing::vga_camera());
  const IcpResult pyramid = align(pair, point_to_point_params(3));
  expect_recovered(pyramid, pair, "pyramid");
  EXPECT_GT(pyramid.fitness, 0.85);
}

TEST_P(IcpEngineTest, PointToPointRecoversKnownMotionWithoutPyramid) {
  // From half the motion: beyond that, the closest point within a pixel is not the right one and
  // the first steps go astray.
  const FramePair pair =
      make_pair(testing::corner_scene(), testing::corner_scene(),
                camera_motion(1.5, {1, 2, 0.5}, {0.02, -0.01, 0.015}), testing::vga_camera());
  IcpParams single = point_to_point_params(1);
  single.levels[0] = {100, 8, 0.15, 0.05, 1};
  expect_recovered(align(pair, single), pair, "single_level");
}

TEST_P(IcpEngineTest, DeviceAgreesWithCpu) {
  // Stated tolerance: 1e-4 deg and 1e-5 m between backends, fitness within 1e-3. The pairs are
  // the same up to pixels exactly half-way between two (rounding of the projection), and the
  // sums agree to ~1e-12 relative (icp_sums_test).
  const FramePair pair = make_pair(testing::corner_scene(), testing::corner_scene(), kMotion);
  const compute::Context cpu = compute::Context::cpu();
  for (const IcpParams& params : {point_to_plane_params(3), point_to_point_params(3)}) {
    const IcpResult device = align(pair, params);
    const IcpResult reference = align_on(cpu, pair, params, Eigen::Isometry3d::Identity());
    EXPECT_LT(testing::rotation_error_deg(device.source_to_target, reference.source_to_target),
              1e-4);
    EXPECT_LT(testing::translation_error(device.source_to_target, reference.source_to_target),
              1e-5);
    EXPECT_NEAR(device.fitness, reference.fitness, 1e-3);
    EXPECT_NEAR(device.inlier_rmse, reference.inlier_rmse, 1e-6);
    EXPECT_LT((device.information - reference.information).norm(),
              1e-3 * reference.information.norm());
  }
}

TEST_P(IcpEngineTest, FlagsASinglePlaneAsDegenerate) {
  const FramePair plane = make_pair(testing::plane_scene(), testing::plane_scene(),
                                    camera_motion(0.5, {1, 0, 0}, {0.0, 0.0, 0.01}));
  const IcpResult result = align(plane, point_to_plane_params(3));
  EXPECT_TRUE(result.degeneracy.degenerate);
  EXPECT_LT(result.degeneracy.eigenvalue_ratio, 1e-6);
  EXPECT_TRUE(result.source_to_target.matrix().allFinite());
  // The wall's normal: tilt and distance are still recovered.
  const Eigen::Vector3d normal =
      testing::reference_camera().linear().transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d estimated = result.source_to_target.linear() * normal;
  const Eigen::Vector3d expected = plane.truth.linear() * normal;
  EXPECT_LT(std::acos(std::min(1.0, estimated.dot(expected))) * 180 / std::numbers::pi, 0.05);
  RecordProperty("plane_eigenvalue_ratio", testing::scientific(result.degeneracy.eigenvalue_ratio));

  const FramePair corner = make_pair(testing::corner_scene(), testing::corner_scene(), kMotion);
  const IcpResult well_posed = align(corner, point_to_plane_params(3));
  EXPECT_FALSE(well_posed.degeneracy.degenerate);
  EXPECT_GT(well_posed.degeneracy.eigenvalue_ratio, 0.05);
  RecordProperty("corner_eigenvalue_ratio",
                 testing::scientific(well_posed.degeneracy.eigenvalue_ratio));
}

// A prior decides what the geometry leaves free and nothing else: ICP of a plane onto itself from
// the truth, with a weak prior whose mean slides along the plane and turns about its normal,
// follows the prior in those three directions and keeps the truth's distance and tilt.
TEST_P(IcpEngineTest, PriorDecidesOnlyTheDirectionsThePlaneLeavesFree) {
  const FramePair plane = make_pair(testing::plane_scene(), testing::plane_scene(),
                                    camera_motion(0.5, {1, 0, 0}, {0.0, 0.0, 0.01}));
  const IcpParams params = point_to_plane_params(3);
  registration::PyramidParams pyramid;
  pyramid.levels = 3;
  const FramePyramid source =
      registration::make_frame_pyramid(context(), plane.camera, plane.source, nullptr, pyramid);
  const FramePyramid target =
      registration::make_frame_pyramid(context(), plane.camera, plane.target, nullptr, pyramid);
  // The source camera looks straight at the plane: free are x, y and the turn about z.
  se3::Vector6d slide;
  slide << 0, 0, 0.02, 0.03, -0.02, 0;
  registration::IcpPrior prior;
  prior.mean = plane.truth * se3::exp(slide);
  prior.information = 1e-2 * se3::Matrix6d::Identity();
  IcpEngine engine(context(), params);
  const IcpResult free = engine.align(source.views(), target.views(), plane.truth);
  const IcpResult held = engine.align(source.views(), target.views(), plane.truth, prior);
  EXPECT_LT(testing::translation_error(free.source_to_target, plane.truth), 0.002);
  // The prior moves the result 3.6 cm and 1.15 degrees, to within 15 % of its mean (the plane's
  // edges are not entirely free).
  EXPECT_GT(testing::translation_error(free.source_to_target, prior.mean), 0.03);
  EXPECT_LT(testing::translation_error(held.source_to_target, prior.mean), 0.005);
  EXPECT_LT(testing::rotation_error_deg(held.source_to_target, prior.mean), 0.3);
  // The plane's distance and normal stay the truth's (the prior's mean shares them).
  const Eigen::Vector3d normal =
      testing::reference_camera().linear().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR((held.source_to_target.linear() * normal).dot(plane.truth.linear() * normal), 1.0,
              1e-6);
  // A NaN prior is bad input.
  prior.information(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(engine.align(source.views(), target.views(), plane.truth, prior), Error);
}

TEST_P(IcpEngineTest, RobustKernelsDownWeightAMovedObject) {
  // The tall box moved 4 cm between the frames; wide gates let its pairs in. Plain least squares
  // is pulled towards the box's motion, Tukey ignores it and Huber bounds its pull.
  testing::Scene moved = testing::corner_scene();
  moved.objects[1].box_to_world.pretranslate(Eigen::Vector3d(0.04, 0.0, -0.03));
  moved.objects[0].box_to_world.pretranslate(Eigen::Vector3d(-0.03, 0.0, 0.03));
  const FramePair pair = make_pair(testing::corner_scene(), moved, kMotion);
  IcpParams params = point_to_plane_params(3);
  for (IcpLevelParams& level : params.levels) level.max_distance = 0.15;
  params.levels[0].robust_scale = 0.01;
  const IcpResult plain = align(pair, params);
  params.robust_kernel = registration::RobustKernel::tukey;
  const IcpResult tukey = align(pair, params);
  params.robust_kernel = registration::RobustKernel::huber;
  const IcpResult huber = align(pair, params);
  const auto error = [&](const IcpResult& r) {
    return testing::translation_error(r.source_to_target, pair.truth);
  };
  EXPECT_GT(error(plain), 0.003);  // the outliers do bias plain least squares
  EXPECT_LT(error(tukey), 0.001);
  EXPECT_LT(testing::rotation_error_deg(tukey.source_to_target, pair.truth), 0.05);
  EXPECT_LT(error(huber), 0.5 * error(plain));
  RecordProperty("plain_translation_error_m", testing::scientific(error(plain)));
  RecordProperty("huber_translation_error_m", testing::scientific(error(huber)));
  RecordProperty("tukey_translation_error_m", testing::scientific(error(tukey)));
}

TEST_P(IcpEngineTest, FitnessAndRmseOnAKnownOverlap) {
  // The camera slides 40 cm sideways: part of the source view leaves the target's. Expected
  // values: the gates applied in double to the true pose, pixel by pixel (all points selected).
  const FramePair pair = make_pair(testing::corner_scene(), testing::corner_scene(),
                                   camera_motion(2.0, {0, 1, 0}, {0.4, 0.0, 0.05}));
  IcpParams params = point_to_plane_params(3);
  params.levels[0].max_distance = 0.01;
  const Eigen::Isometry3d initial = Eigen::Translation3d(0.005, 0.002, 0) * pair.truth;
  const IcpResult result = align(pair, params, initial);
  expect_recovered(result, pair, "overlap");

  const compute::Context cpu = compute::Context::cpu();
  const NormalImage source_normals = geometry::estimate_normals(cpu, pair.source);
  const NormalImage target_normals = geometry::estimate_normals(cpu, pair.target);
  const PinholeIntrinsics& k = pair.camera;
  std::size_t considered = 0, inliers = 0;
  double squared = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      if (!is_valid(pair.source(u, v))) continue;
      ++considered;
      const Eigen::Vector3d p =
          result.source_to_target * pair.source(u, v).head<3>().cast<double>();
      const long x = std::lround(k.fx * p.x() / p.z() + k.cx),
                 y = std::lround(k.fy * p.y() / p.z() + k.cy);
      if (x < 0 || y < 0 || x >= k.width || y >= k.height) continue;
      const Point4f& q = pair.target(static_cast<int>(x), static_cast<int>(y));
      const Point4f& nq = target_normals(static_cast<int>(x), static_cast<int>(y));
      const Point4f& np = source_normals(u, v);
      if (!is_valid(q) || !is_valid(nq) || !is_valid(np)) continue;
      if ((p - q.head<3>().cast<double>()).norm() > 0.01) continue;
      const Eigen::Vector3d n = nq.head<3>().cast<double>();
      if ((result.source_to_target.linear() * np.head<3>().cast<double>()).dot(n) <
          std::cos(std::numbers::pi / 6))
        continue;
      ++inliers;
      squared += std::pow((p - q.head<3>().cast<double>()).dot(n), 2);
    }
  }
  const double fitness = static_cast<double>(inliers) / static_cast<double>(considered);
  EXPECT_EQ(result.considered_count, considered);
  EXPECT_NEAR(result.fitness, fitness, 0.002);
  EXPECT_LT(result.fitness, 0.85);  // the overlap is partial
  EXPECT_NEAR(result.inlier_rmse, std::sqrt(squared / static_cast<double>(inliers)), 2e-5);
  EXPECT_LT(result.inlier_rmse, 5e-4);  // noise-free: the plane distances vanish
  RecordProperty("fitness", testing::scientific(result.fitness));
  RecordProperty("reference_fitness", testing::scientific(fitness));
  RecordProperty("inlier_rmse_m", testing::scientific(result.inlier_rmse));
}

// A finder from outside the library: projective association computed on the host (in double)
// and uploaded, with every 7th pair weighted 0. The engine must run it like its own.
class HostReferenceFinder : public registration::CorrespondenceFinder {
 public:
  explicit HostReferenceFinder(const compute::Context& context) : context_(&context) {}
  int prepared_levels = 0;
  void prepare(const registration::CloudView&, int) override { ++prepared_levels; }
  void find(const registration::CloudView& source, const registration::CloudView& target,
            const Eigen::Isometry3d& pose, const registration::AssociationParams& params,
            registration::CorrespondenceBuffers& out) override {
    std::vector<Point4f> points(source.size()), targets(target.size());
    source.points->download(points);
    target.points->download(targets);
    const PinholeIntrinsics& k = *target.camera;
    std::vector<std::int32_t> index(source.size(), registration::kNoMatch);
    std::vector<float> weights(source.size(), 1.0f);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!registration::is_selected(static_cast<std::uint32_t>(i), source.camera->width,
                                     params.subsample)) {
        index[i] = registration::kNotSelected;
        continue;
      }
      if (!is_valid(points[i])) continue;
      const Eigen::Vector3d p = pose * points[i].head<3>().cast<double>();
      const long x = std::lround(k.fx * p.x() / p.z() + k.cx),
                 y = std::lround(k.fy * p.y() / p.z() + k.cy);
      if (p.z() <= 0 || x < 0 || y < 0 || x >= k.width || y >= k.height) continue;
      const std::size_t j = static_cast<std::size_t>(y * k.width + x);
      if (is_valid(targets[j]) &&
          (p - targets[j].head<3>().cast<double>()).norm() <= params.max_distance) {
        index[i] = static_cast<std::int32_t>(j);
      }
      if (i % 7 == 0) weights[i] = 0.0f;
    }
    out.target_index = compute::Buffer<std::int32_t>::from_host(*context_, index);
    out.weights = compute::Buffer<float>::from_host(*context_, weights);
  }

 private:
  const compute::Context* context_;
};

TEST_P(IcpEngineTest, RunsAPluggedInFinder) {
  const FramePair pair = make_pair(testing::corner_scene(), testing::corner_scene(), kMotion);
  auto finder = std::make_unique<HostReferenceFinder>(context());
  HostReferenceFinder* seen = finder.get();
  IcpParams params = point_to_plane_params(3);
  registration::PyramidParams pyramid;
  const FramePyramid source =
      registration::make_frame_pyramid(context(), pair.camera, pair.source, nullptr, pyramid);
  const FramePyramid target =
      registration::make_frame_pyramid(context(), pair.camera, pair.target, nullptr, pyramid);
  IcpEngine engine(context(), params, std::move(finder));
  const IcpResult result = engine.align(source, target);
  expect_recovered(result, pair, "plugged_in");
  EXPECT_EQ(seen->prepared_levels, 3);
  // Weight-0 pairs are considered but are no inliers: fitness <= 6/7.
  EXPECT_LT(result.fitness, 6.0 / 7.0 + 1e-3);
  EXPECT_GT(result.fitness, 0.7);
}

TEST_P(IcpEngineTest, RejectsBadInput) {
  IcpParams params;
  params.levels.clear();
  EXPECT_THROW(IcpEngine(context(), params), Error);
  params = IcpParams{};
  params.levels[1].subsample = 0;
  EXPECT_THROW(IcpEngine(context(), params), Error);
  params = IcpParams{};
  params.robust_kernel = registration::RobustKernel::huber;
  params.levels[0].robust_scale = 0;
  EXPECT_THROW(IcpEngine(context(), params), Error);
  params = IcpParams{};
  params.min_eigenvalue_ratio = 2;
  EXPECT_THROW(IcpEngine(context(), params), Error);

  const PinholeIntrinsics camera = testing::qvga_camera();
  const PointImage points =
      testing::render(testing::corner_scene(), camera, testing::reference_camera());
  registration::PyramidParams two;
  two.levels = 2;
  const FramePyramid shallow =
      registration::make_frame_pyramid(context(), camera, points, nullptr, two);
  IcpEngine engine(context());  // three levels
  EXPECT_THROW(engine.align(shallow, shallow), Error);
  const FramePyramid frame = registration::make_frame_pyramid(context(), camera, points);
  std::vector<registration::CloudView> no_normals = frame.views();
  for (auto& view : no_normals) view.normals = nullptr;
  EXPECT_THROW(engine.align(frame.views(), no_normals), Error);
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().y() = std::nan("");
  EXPECT_THROW(engine.align(frame, frame, bad), Error);

  // An empty target is no error: no pairs, not converged, fitness 0.
  const FramePyramid empty = registration::make_frame_pyramid(
      context(), camera, PointImage(camera.width, camera.height, invalid_point()));
  const IcpResult nothing = engine.align(frame, empty);
  EXPECT_FALSE(nothing.converged);
  EXPECT_EQ(nothing.inlier_count, 0u);
  EXPECT_EQ(nothing.fitness, 0.0);
  EXPECT_TRUE(nothing.degeneracy.degenerate);
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(IcpEngineTest);

// The CPU backend splits its loops into fixed chunks, so the thread count changes nothing.
TEST(IcpEngineCpuThreads, ResultsDoNotDependOnTheThreadCount) {
  const char* previous = std::getenv("KARTOGRAF_CPU_THREADS");
  const std::string saved = previous ? previous : "";
  const FramePair pair =
      make_pair(testing::corner_scene(), testing::corner_scene(), kMotion, testing::vga_camera());
  const compute::Context cpu = compute::Context::cpu();
  const auto run = [&](const char* threads) {
    ::setenv("KARTOGRAF_CPU_THREADS", threads, 1);
    registration::PyramidParams params;
    const FramePyramid source =
        registration::make_frame_pyramid(cpu, pair.camera, pair.source, nullptr, params);
    const FramePyramid target =
        registration::make_frame_pyramid(cpu, pair.camera, pair.target, nullptr, params);
    IcpParams icp;
    icp.levels[0].subsample = 1;  // enough points for the threaded path at every level
    return IcpEngine(cpu, icp).align(source, target);
  };
  const IcpResult one = run("1"), three = run("3");
  EXPECT_EQ(one.source_to_target.matrix(), three.source_to_target.matrix());
  EXPECT_EQ(one.information, three.information);
  EXPECT_EQ(one.inlier_count, three.inlier_count);
  EXPECT_THROW(run("0"), Error);
  if (previous) {
    ::setenv("KARTOGRAF_CPU_THREADS", saved.c_str(), 1);
  } else {
    ::unsetenv("KARTOGRAF_CPU_THREADS");
  }
}

}  // namespace
}  // namespace kartograf
