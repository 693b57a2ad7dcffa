// Frame-to-model tracking (mapping/model_tracking.hpp) on the synthetic world: predictions that
// are off by a few millimetres are corrected against the model, implausible corrections leave the
// prediction, and the first frame only starts the model.
#include <gtest/gtest.h>

#include <cmath>

#include "kartograf/compute/context.hpp"
#include "kartograf/mapping/model_tracking.hpp"
#include "kartograf/synth/render.hpp"
#include "kartograf/synth/trajectory.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf {
namespace {

const PinholeIntrinsics kCamera{320, 240, 262.5, 262.5, 159.5, 119.5};

Eigen::Isometry3d nudged(const Eigen::Isometry3d& pose, double metres, double degrees, int i) {
  const Eigen::Vector3d axis = Eigen::Vector3d(std::cos(i), std::sin(i), 0.5).normalized();
  Eigen::Isometry3d error = Eigen::Isometry3d::Identity();
  error.linear() = Eigen::AngleAxisd(degrees * M_PI / 180, axis).toRotationMatrix();
  error.translation() =
      metres * Eigen::Vector3d(std::sin(2 * i), std::cos(3 * i), 0.3).normalized();
  return pose * error;
}

double distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

// A tour of synthetic building 5 and trackers on the CPU backend.
class ModelTracking : public ::testing::Test {
 protected:
  mapping::ModelTracker tracker(const mapping::ModelTrackingParams& params) const {
    return mapping::ModelTracker(cpu, kCamera, {5000.0, 0.3, 4.0}, params);
  }
  static mapping::ModelTrackingParams enabled() {
    mapping::ModelTrackingParams params;
    params.enabled = true;
    return params;
  }
  synth::SyntheticFrame frame(int i) const {
    return synth::render(world, kCamera, pose(i), synth::NoiseModel{}, i);
  }
  const Eigen::Isometry3d& pose(int i) const { return tour[static_cast<std::size_t>(i)].pose; }

  const synth::World world = synth::make_building(5);
  const Trajectory tour = synth::robot_tour(world, synth::tour_frames_needed(world));
  const compute::Context cpu = compute::Context::cpu();
};

// The first frame starts the model where it truly is; the next frames' predictions are 1 cm and
// 0.3 degrees off. Over whole sequences the model's noise at range (the synthetic sensor
// quantises 4 m depth in 5 cm steps) makes the tracker no better than frame-to-frame yet
// (docs/volumetric.md): this checks the mechanism, on views the model has seen.
//
// With the frame-to-frame depth weights: the default 1 / z^4 over the whole range lets this
// tour's near floor decide, so frame 2 is degenerate and the motion prior holds the (nudged)
// prediction in its weak directions, as designed.
TEST_F(ModelTracking, CorrectsNudgedPredictionsAgainstTheModel) {
  mapping::ModelTrackingParams params = enabled();
  params.depth_weights.reference_depth = 1.5;
  mapping::ModelTracker tracking = tracker(params);
  for (int i = 0; i < 3; ++i) {
    const synth::SyntheticFrame sensed = frame(i);
    const Eigen::Isometry3d predicted = i == 0 ? pose(i) : nudged(pose(i), 0.01, 0.3, i);
    const mapping::ModelTrackingStep step = tracking.track(sensed.depth, &sensed.color, predicted);
    if (i == 0) {
      EXPECT_EQ(step.reason, "first frame");
      EXPECT_FALSE(step.from_model);
      continue;
    }
    EXPECT_TRUE(step.from_model) << step.reason;
    EXPECT_GT(step.fitness, 0.4);
    EXPECT_LT(distance(step.pose, pose(i)), 0.002) << "frame " << i;
  }
}

// The odometry's pyramid of the frame, given to the tracker, gives the poses of the tracker's
// own; a pyramid of another camera, or without ICP's levels, is an error.
TEST_F(ModelTracking, AGivenPyramidGivesThePosesOfItsOwn) {
  mapping::ModelTracker own = tracker(enabled());
  mapping::ModelTracker shared = tracker(enabled());
  const geometry::DepthRange range{5000.0, 0.3, 4.0};
  const geometry::DepthBackprojector projector(cpu, kCamera, range);
  registration::PyramidParams levels;
  levels.levels = 4;               // ICP from 160x120 (level 1), three levels
  levels.first_normals_level = 1;  // the geometric information at 80x60 (level 2)
  registration::FramePyramid pyramid(cpu, kCamera, levels);
  for (int i = 0; i < 3; ++i) {
    const synth::SyntheticFrame sensed = frame(i);
    const Eigen::Isometry3d predicted = nudged(pose(i), 0.01, 0.3, i);
    pyramid.build(projector, compute::DeviceImage<std::uint16_t>::from_host(cpu, sensed.depth));
    const mapping::ModelTrackingStep a = own.track(sensed.depth, &sensed.color, predicted);
    const mapping::ModelTrackingStep b =
        shared.track(sensed.depth, &sensed.color, predicted, &pyramid);
    EXPECT_TRUE(a.pose.isApprox(b.pose, 0)) << "frame " << i;
    EXPECT_EQ(a.fitness, b.fitness);
  }
  const synth::SyntheticFrame sensed = frame(3);
  levels.levels = 3;
  const registration::FramePyramid short_one(cpu, kCamera, levels);
  EXPECT_TRUE(shared.can_register(pyramid));
  EXPECT_FALSE(shared.can_register(short_one));
  EXPECT_THROW(shared.track(sensed.depth, nullptr, pose(3), &short_one), Error);
  const registration::FramePyramid no_normals(cpu, kCamera, [] {
    registration::PyramidParams p;
    p.levels = 4;
    p.first_normals_level = 2;
    return p;
  }());
  EXPECT_FALSE(shared.can_register(no_normals));
  EXPECT_THROW(shared.track(sensed.depth, nullptr, pose(3), &no_normals), Error);
  const PinholeIntrinsics other{320, 240, 250.0, 250.0, 159.5, 119.5};
  levels.levels = 4;
  const registration::FramePyramid other_camera(cpu, other, levels);
  EXPECT_FALSE(shared.can_register(other_camera));
  EXPECT_THROW(shared.track(sensed.depth, nullptr, pose(3), &other_camera), Error);
  // The given pyramid is what ICP registers: one of another frame moves the answer.
  pyramid.build(projector, compute::DeviceImage<std::uint16_t>::from_host(cpu, frame(8).depth));
  const Eigen::Isometry3d predicted = nudged(pose(3), 0.01, 0.3, 3);
  EXPECT_FALSE(
      own.track(sensed.depth, nullptr, predicted)
          .pose.isApprox(shared.track(sensed.depth, nullptr, predicted, &pyramid).pose, 1e-9));
}

TEST_F(ModelTracking, AnImplausibleCorrectionLeavesThePrediction) {
  mapping::ModelTrackingParams params = enabled();
  params.max_correction_m = 0.005;
  mapping::ModelTracker tracking = tracker(params);
  tracking.track(frame(0).depth, nullptr, pose(0));
  const Eigen::Isometry3d predicted = nudged(pose(1), 0.03, 0, 1);
  const mapping::ModelTrackingStep step = tracking.track(frame(1).depth, nullptr, predicted);
  EXPECT_FALSE(step.from_model);
  EXPECT_EQ(step.reason, "moved the prediction too far");
  EXPECT_TRUE(step.pose.isApprox(predicted));
}

// A pool too small for the tour: when it is three quarters full the blocks the camera has not
// seen for longest go, down to half of that, and the frames go on being tracked against what
// stayed (what the camera was looking at: the next frame adds few blocks back).
TEST_F(ModelTracking, AFullModelEvictsWhatTheCameraHasNotSeenLately) {
  mapping::ModelTrackingParams params = enabled();
  params.depth_weights.reference_depth = 1.5;  // as in CorrectsNudgedPredictionsAgainstTheModel
  params.volume.max_blocks = 3000;             // the tour's first 60 frames fill about 4000
  mapping::ModelTracker tracking = tracker(params);
  std::size_t evictions = 0, from_model = 0;
  for (int i = 0; i < 60; i += 2) {
    const synth::SyntheticFrame sensed = frame(i);
    const std::size_t before = tracking.volume().block_count();
    const mapping::ModelTrackingStep step =
        tracking.track(sensed.depth, nullptr, nudged(pose(i), 0.005, 0.1, i));
    EXPECT_LE(tracking.volume().block_count(), 2400u);
    EXPECT_LT(distance(step.pose, pose(i)), 0.01) << "frame " << i;
    from_model += step.from_model ? 1 : 0;
    if (step.evicted_blocks == 0) continue;
    ++evictions;
    EXPECT_GE(before, 1800u);                                         // three quarters of the pool
    EXPECT_EQ(before - step.evicted_blocks, 1125u) << "frame " << i;  // half of 3/4
    EXPECT_LT(tracking.volume().block_count(), 1125u + 400u) << "frame " << i;
  }
  EXPECT_GE(evictions, 1u);
  EXPECT_GE(from_model, 15u);
}

TEST_F(ModelTracking, BadParametersAreRefused) {
  for (auto change : std::initializer_list<void (*)(mapping::ModelTrackingParams&)>{
           [](mapping::ModelTrackingParams& p) { p.min_fitness = 1.5; },
           [](mapping::ModelTrackingParams& p) { p.max_correction_m = 0; },
           [](mapping::ModelTrackingParams& p) { p.icp_width = 0; },
           [](mapping::ModelTrackingParams& p) { p.evict_fill = 0; },
           [](mapping::ModelTrackingParams& p) { p.volume.voxel_size = -1; }}) {
    mapping::ModelTrackingParams p;
    change(p);
    EXPECT_THROW(tracker(p), Error);
  }
}

}  // namespace
}  // namespace kartograf
