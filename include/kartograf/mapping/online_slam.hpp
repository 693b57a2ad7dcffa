#pragma once
// The SLAM of slam.hpp one frame at a time: a robot hands each frame over as it comes and gets its
// pose back at once. run_slam is this loop over a FrameSource, so both give the same poses.
//
// add() tracks the frame (RgbdOdometry), and on a keyframe searches and verifies loop closures;
// when one is accepted the pose graph is optimised and every earlier pose may move (the step says
// so). finish() optimises the whole graph once more, prunes inconsistent loop closures and
// returns the run (without a fused map: run_slam's second pass builds that).
#include <cstddef>
#include <memory>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/mapping/slam.hpp"
#include "kartograf/registration/rgbd_frame.hpp"

namespace kartograf::mapping {

struct SlamStep {
  std::size_t frame = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // camera-to-world, the current estimate
  registration::OdometryFrame odometry;                    // the tracking's report
  // A loop closure was accepted and the graph optimised: the poses of earlier frames moved.
  bool optimised = false;
};

class OnlineSlam {
 public:
  // depth_units_per_metre: the frames' depth units (replaces params.odometry's). Throws Error on
  // invalid intrinsics or parameters.
  OnlineSlam(const compute::Context& context, const PinholeIntrinsics& camera,
             double depth_units_per_metre, const SlamParams& params,
             const SlamObserver& observer = {});
  ~OnlineSlam();
  OnlineSlam(OnlineSlam&&) noexcept;
  OnlineSlam& operator=(OnlineSlam&&) noexcept;

  // Tracks the next frame. Throws Error on a frame the odometry cannot take (size, missing
  // colour where the method needs it) or after finish().
  SlamStep add(const registration::RgbdImages& images);

  std::size_t frame_count() const;
  // The current estimate of every frame so far (camera-to-world, frame 0 = identity).
  const std::vector<Eigen::Isometry3d>& poses() const;
  // The loop closure's keyframes (depth, samples, features): bytes in memory, bytes in its
  // temporary files (0 without loop closure).
  std::size_t keyframe_bytes_in_memory() const;
  std::size_t keyframe_bytes_on_disk() const;

  // The final optimisation; the result's map is empty and its timing holds the compute times
  // (load times are the caller's). Once only: later calls to add() or finish() throw Error.
  SlamResult finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace kartograf::mapping
