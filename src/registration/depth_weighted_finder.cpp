#include "kartograf/registration/depth_weighted_finder.hpp"

#include <algorithm>
#include <cmath>
#include <span>

namespace kartograf::registration {

DepthWeightedFinder::DepthWeightedFinder(const compute::Context& context,
                                         std::unique_ptr<CorrespondenceFinder> inner,
                                         DepthWeightParams params)
    : context_(&context), inner_(std::move(inner)), params_(params) {
  require(inner_ != nullptr, "depth-weighted finder: an inner finder is required");
  require(std::isfinite(params_.reference_depth) && params_.reference_depth > 0,
          "depth-weighted finder: reference_depth must be finite and > 0");
}

float DepthWeightedFinder::weight(float z, double reference_depth) {
  if (!(z > 0)) return 0.0f;  // NaN (invalid point) or behind the camera
  const double ratio = std::min(1.0, reference_depth / z);
  const double squared = ratio * ratio;
  return static_cast<float>(squared * squared);
}

void DepthWeightedFinder::prepare(const CloudView& target, int level) {
  stale_ = true;  // the engine prepares each level right before its first find()
  inner_->prepare(target, level);
}

void DepthWeightedFinder::write_weights(const CloudView& source, compute::Buffer<float>& weights) {
  const std::size_t count = source.size();
  if (weights.size() != count) weights = compute::Buffer<float>(*context_, count);
  // On the host (in place on the CPU backend): a few hundred thousand points once per level.
  const auto points = compute::read_on_host(*source.points);
  auto out = compute::write_on_host(weights, compute::HostWriteStart::overwrite_all);
  for (std::size_t i = 0; i < count; ++i) out[i] = weight(points[i].z(), params_.reference_depth);
}

void DepthWeightedFinder::find(const CloudView& source, const CloudView& target,
                               const Eigen::Isometry3d& source_to_target,
                               const AssociationParams& params, CorrespondenceBuffers& out) {
  require(source.points != nullptr, "depth-weighted finder: source points are required");
  inner_->find(source, target, source_to_target, params, out);
  if (stale_ || out.weights.size() != source.size()) {
    write_weights(source, out.weights);
    stale_ = false;
  }
}

}  // namespace kartograf::registration
