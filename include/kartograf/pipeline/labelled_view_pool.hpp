#pragma once
// One view labelled (semantic/classify.hpp) and pooled in the world frame
// (semantic/labelled_views.hpp): what `kartograf map`'s views stage does with every label_step-th
// frame and `kartograf semantic` with each frame or range image.
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/semantic/classify.hpp"
#include "kartograf/semantic/labelled_views.hpp"

namespace kartograf::pipeline {

// Labels `points` (organized, in the sensor frame) and adds them to `views` at `sensor_to_world`;
// returns the labelling. A view that cannot be labelled (e.g. a wall seen from close by: no floor
// or ceiling to find up from) is skipped in `views`, the reason prefixed by `skip_prefix`, and
// nothing is returned. With `failure`, the reason goes there instead and `views` counts nothing
// (the caller may try again, e.g. with a known up).
std::optional<semantic::SemanticLabelling> label_and_pool_view(
    const compute::Context& context, const PointImage& points,
    const Eigen::Isometry3d& sensor_to_world, const semantic::LabellingParams& params,
    semantic::LabelledViews& views, const std::string& skip_prefix = {},
    std::string* failure = nullptr);

}  // namespace kartograf::pipeline
