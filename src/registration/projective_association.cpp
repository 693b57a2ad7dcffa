#include "kartograf/registration/projective_association.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kernels/projective_association/projective_association.h"
#include "registration/association_checks.hpp"

namespace kartograf::registration {

namespace {

constexpr compute::KernelSpec kAssociationKernel{"projective_association",
                                                 KG_PROJECTIVE_ASSOCIATION_LOCAL_X};
constexpr std::size_t kFrameValues = KG_ASSOCIATION_FRAME_VALUES;
using Frame = std::array<float, kFrameValues>;
static_assert(KG_ASSOCIATION_NO_MATCH == kNoMatch && KG_ASSOCIATION_NOT_SELECTED == kNotSelected,
              "the kernels' correspondence codes are icp_sums.hpp's");

bool normal_gate_on(const AssociationParams& params) {
  return params.max_normal_angle_deg < 180.0;
}

// The frame buffer's slots (KG_ASSOCIATION_FRAME_*), rounded from double once.
Frame frame_values(const Eigen::Isometry3d& pose, const PinholeIntrinsics& camera,
                   const AssociationParams& params) {
  std::array<double, kFrameValues> values{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) values[KG_ASSOCIATION_FRAME_R + 3 * r + c] = pose.linear()(r, c);
    values[KG_ASSOCIATION_FRAME_T + r] = pose.translation()(r);
  }
  values[KG_ASSOCIATION_FRAME_FX] = camera.fx;
  values[KG_ASSOCIATION_FRAME_FY] = camera.fy;
  values[KG_ASSOCIATION_FRAME_CX] = camera.cx;
  values[KG_ASSOCIATION_FRAME_CY] = camera.cy;
  values[KG_ASSOCIATION_FRAME_MAX_DISTANCE_SQ] = params.max_distance * params.max_distance;
  values[KG_ASSOCIATION_FRAME_MIN_COSINE] =
      std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
  Frame frame{};
  for (std::size_t k = 0; k < kFrameValues; ++k) frame[k] = static_cast<float>(values[k]);
  return frame;
}

void validate(const CloudView& source, const CloudView& target, const AssociationParams& params,
              bool use_normals) {
  const std::string what = "projective association: ";
  detail::check_association_inputs(source, target, params, use_normals, "projective association");
  require(target.camera.has_value(), what + "the target must be organized (have a camera)");
  target.camera->validate(what + "target camera");
  require(target.points->size() == static_cast<std::size_t>(target.camera->width) *
                                       static_cast<std::size_t>(target.camera->height),
          what + "target points (" + std::to_string(target.points->size()) +
              ") do not match the target camera's " + std::to_string(target.camera->width) + "x" +
              std::to_string(target.camera->height));
  require(params.search_radius >= 0 && params.search_radius <= 16,
          what + "search_radius must be 0..16, got " + std::to_string(params.search_radius));
  require(params.max_distance >= 0 && std::isfinite(params.max_distance),
          what + "max_distance must be finite and >= 0");
}

}  // namespace

ProjectiveAssociation::ProjectiveAssociation(const compute::Context& context) : context_(&context) {
  frame_ = compute::Buffer<float>(context, kFrameValues);
}

void ProjectiveAssociation::find(const CloudView& source, const CloudView& target,
                                 const Eigen::Isometry3d& source_to_target,
                                 const AssociationParams& params, CorrespondenceBuffers& out) {
  const bool use_normals = normal_gate_on(params);
  validate(source, target, params, use_normals);
  require(source_to_target.matrix().allFinite(),
          "projective association: the pose has NaN/Inf entries");
  if (out.target_index.size() != source.size()) {
    out.target_index = compute::Buffer<std::int32_t>(*context_, source.size());
  }
  const Frame frame = frame_values(source_to_target, *target.camera, params);
  const auto k = static_cast<std::uint32_t>(params.subsample);
  if (source.size() == 0) return;
  frame_.upload(frame);
  const kernels::ProjectiveAssociationParams kernel_params{
      static_cast<std::uint32_t>(source.size()),
      source.camera ? static_cast<std::uint32_t>(source.camera->width) : 0u,
      static_cast<std::uint32_t>(target.camera->width),
      static_cast<std::uint32_t>(target.camera->height),
      k,
      use_normals ? 1u : 0u,
      static_cast<std::uint32_t>(params.search_radius)};
  const compute::BufferArg source_normals =
      use_normals ? compute::BufferArg(*source.normals) : compute::BufferArg();
  const compute::BufferArg target_normals =
      use_normals ? compute::BufferArg(*target.normals) : compute::BufferArg();
  compute::dispatch(
      *context_, kAssociationKernel,
      {*source.points, source_normals, *target.points, target_normals, frame_, out.target_index},
      kernel_params, {compute::groups_for(source.size(), kAssociationKernel.local_x), 1});
}

}  // namespace kartograf::registration
