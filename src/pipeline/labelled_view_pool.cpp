#include "kartograf/pipeline/labelled_view_pool.hpp"

#include "kartograf/core/error.hpp"

namespace kartograf::pipeline {

std::optional<semantic::SemanticLabelling> label_and_pool_view(
    const compute::Context& context, const PointImage& points,
    const Eigen::Isometry3d& sensor_to_world, const semantic::LabellingParams& params,
    semantic::LabelledViews& views, const std::string& skip_prefix, std::string* failure) {
  try {
    semantic::SemanticLabelling labelling =
        semantic::label_organized_points(context, points, params);
    views.add(points, labelling.semantic, labelling.gravity, sensor_to_world);
    return labelling;
  } catch (const Error& e) {
    if (failure) {
      *failure = skip_prefix + e.what();
    } else {
      views.skip(skip_prefix + e.what());
    }
    return std::nullopt;
  }
}

}  // namespace kartograf::pipeline
