#pragma once
// Pair weights for depth-camera noise: a correspondence finder decorator that weights every source
// point by the inverse variance of its depth, w = min(1, (reference_depth / z)^4). Structured-light
// and stereo depth errors grow as z^2 (axial noise, and disparity quantisation: 5 cm steps at 4 m
// on a Kinect), so distant points otherwise dominate the sums with errors that do not average out:
// on the synthetic robot tour, frame-to-frame point-to-plane ICP looking down a corridor
// underestimated the forward motion by ~10 % unweighted and not measurably with these weights.
//
// The weights depend only on the source frame, so they are written once per align() and level
// (prepare() marks them stale; the level's first find() computes them from the source points' z, on
// the host) and stay in the engine's per-level buffer for the following iterations; the inner
// finder's pairs pass through unchanged. On a device backend that costs one download of the
// level's points and one upload of its weights per align().
#include <memory>
#include <vector>

#include "kartograf/registration/correspondence_finder.hpp"

namespace kartograf::registration {

struct DepthWeightParams {
  double reference_depth = 1.5;  // metres: nearer points get weight 1
};

class DepthWeightedFinder : public CorrespondenceFinder {
 public:
  // Throws Error for reference_depth not finite and > 0.
  DepthWeightedFinder(const compute::Context& context, std::unique_ptr<CorrespondenceFinder> inner,
                      DepthWeightParams params = {});

  void prepare(const CloudView& target, int level) override;
  void find(const CloudView& source, const CloudView& target,
            const Eigen::Isometry3d& source_to_target, const AssociationParams& params,
            CorrespondenceBuffers& out) override;

  // The weight of a point at depth z (0 for invalid points).
  static float weight(float z, double reference_depth);

 private:
  void write_weights(const CloudView& source, compute::Buffer<float>& weights);

  const compute::Context* context_;
  std::unique_ptr<CorrespondenceFinder> inner_;
  DepthWeightParams params_;
  bool stale_ = true;  // prepare() was called: the next find() writes the weights
};

}  // namespace kartograf::registration
