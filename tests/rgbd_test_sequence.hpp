#pragma once
// Small RGB-D sequences rendered in memory from the synthetic world (synth/), for the odometry,
// loop-closure and SLAM tests: exact ground truth, Kinect-like noise, 320x240 to stay fast.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/mapping/frame_source.hpp"
#include "kartograf/registration/rgbd_frame.hpp"
#include "kartograf/synth/world.hpp"

namespace kartograf::testing {

inline constexpr double kSynthUnitsPerMetre = 5000.0;

// The default building (seed 1), built once.
const synth::World& test_world();
// 320x240, f = 262.5: the TUM Kinect at half resolution.
PinholeIntrinsics qvga_kinect();
// Poses first, first + stride, ... (count of them) of the survey through `world` (the demo's
// recipe: `kartograf synth --survey --pitch 20`).
std::vector<Eigen::Isometry3d> survey_poses(const synth::World& world, std::size_t first,
                                            std::size_t count, std::size_t stride = 1);

struct RenderedSequence {
  PinholeIntrinsics camera;
  std::vector<Eigen::Isometry3d> truth;  // camera-to-world
  std::vector<registration::RgbdImages> frames;
};

// One frame per pose, timestamps i / 30 s; noise: the Kinect model (seeded per frame) or none.
RenderedSequence render_sequence(const std::vector<Eigen::Isometry3d>& poses,
                                 const PinholeIntrinsics& camera, bool noise = true);
// The same in another world.
RenderedSequence render_sequence(const synth::World& world,
                                 const std::vector<Eigen::Isometry3d>& poses,
                                 const PinholeIntrinsics& camera, bool noise = true);
// The same with each frame's noise seed given (io::synthetic_frame_seed: `kartograf synth`'s own
// frames).
RenderedSequence render_sequence(const synth::World& world,
                                 const std::vector<Eigen::Isometry3d>& poses,
                                 const PinholeIntrinsics& camera,
                                 const std::vector<std::uint64_t>& noise_seeds);

// 30 frames (1.3 m) of the 500-frame robot tour along a furnished room, then back the same way
// (as a robot reversing): the return trip sees again what the way out saw, so SLAM closes loops.
// Rendered once.
const RenderedSequence& out_and_back();

// The pipeline's view of a rendered sequence.
class MemoryFrameSource final : public mapping::FrameSource {
 public:
  explicit MemoryFrameSource(const RenderedSequence& sequence) : sequence_(&sequence) {}
  std::size_t size() const override { return sequence_->frames.size(); }
  PinholeIntrinsics camera() const override { return sequence_->camera; }
  double depth_units_per_metre() const override { return kSynthUnitsPerMetre; }
  registration::RgbdImages frame(std::size_t i) const override { return sequence_->frames.at(i); }

 private:
  const RenderedSequence* sequence_;
};

// ATE RMSE (SE(3)-aligned, eval/trajectory_metrics.hpp) of an estimate against the truth.
double ate_rmse(const std::vector<Eigen::Isometry3d>& estimate,
                const std::vector<Eigen::Isometry3d>& truth);

// A depth image (units_per_metre) of an organized point image: what a sensor would report.
DepthImage depth_of(const PointImage& points, double units_per_metre);

}  // namespace kartograf::testing
