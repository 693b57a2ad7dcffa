// Frame-to-model tracking (mapping/model_tracking.hpp) on every backend against the CPU backend:
// the odometry's prediction, the model's ray cast, ICP and fusion together, with the default
// volume (lowered to fit the device's largest buffer where it is smaller, as on lavapipe).
// Stated tolerance: poses within 1 mm and 0.05 degrees of the CPU's over 8 frames.
#include <gtest/gtest.h>

#include <numbers>
#include <vector>

#include "kartograf/mapping/model_tracking.hpp"
#include "kartograf/registration/odometry.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "rgbd_test_sequence.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The odometry predicts, the model corrects (as mapping::run_odometry does); the poses found.
std::vector<Eigen::Isometry3d> track_against_the_model(const compute::Context& context,
                                                       const testing::RenderedSequence& sequence) {
  mapping::ModelTrackingParams model;
  model.enabled = true;
  registration::OdometryParams odometry_params;
  odometry_params.depth_range.units_per_metre = testing::kSynthUnitsPerMetre;
  registration::RgbdOdometry odometry(context, sequence.camera, model.predicting(odometry_params));
  mapping::ModelTracker tracker(context, sequence.camera, odometry.params().depth_range, model);
  std::vector<Eigen::Isometry3d> poses;
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const registration::RgbdImages& frame = sequence.frames[i];
    odometry.track(frame.depth, &frame.color);
    const auto& odometry_poses = odometry.poses();
    const Eigen::Isometry3d predicted =
        i == 0 ? odometry_poses[0]
               : poses.back() * (odometry_poses[i - 1].inverse() * odometry_poses[i]);
    poses.push_back(
        tracker.track(frame.depth, &frame.color, predicted, &odometry.latest_pyramid()).pose);
  }
  return poses;
}

class ModelTrackingBackends : public testing::BackendTest {};

TEST_P(ModelTrackingBackends, AgreesWithTheCpuBackend) {
  const Trajectory tour = synth::robot_tour(testing::test_world(), 500);
  std::vector<Eigen::Isometry3d> truth;
  for (std::size_t i = 400; i < 408; ++i) truth.push_back(tour[i].pose);
  const testing::RenderedSequence sequence =
      testing::render_sequence(truth, testing::qvga_kinect());
  const std::vector<Eigen::Isometry3d> reference =
      track_against_the_model(compute::Context::cpu(), sequence);
  const std::vector<Eigen::Isometry3d> device = track_against_the_model(context(), sequence);
  ASSERT_EQ(device.size(), reference.size());
  for (std::size_t i = 0; i < device.size(); ++i) {
    const Eigen::Isometry3d difference = reference[i].inverse() * device[i];
    EXPECT_LT(difference.translation().norm(), 1e-3) << i;
    EXPECT_LT(Eigen::AngleAxisd(difference.rotation()).angle(), 0.05 * kDegree) << i;
    // And near the truth: the tracker works on this sequence at all.
    const Eigen::Isometry3d error = (truth[0].inverse() * truth[i]).inverse() * device[i];
    EXPECT_LT(error.translation().norm(), 0.02) << i;
  }
}

KARTOGRAF_INSTANTIATE_BACKEND_TESTS(ModelTrackingBackends);

}  // namespace
}  // namespace kartograf
