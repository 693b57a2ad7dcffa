#include "kartograf/registration/projective_association.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "registration/association_checks.hpp"
#include "compute/cpu_parallel.hpp"

namespace kartograf::registration {

namespace {

constexpr compute::KernelSpec kAssociationKernel{"projective_association", 64};
constexpr std::size_t kFrameValues = 18;
using Frame = std::array<float, kFrameValues>;

struct AssociationKernelParams {  // layout of shaders/projective_association.comp and the .cl
  std::uint32_t source_count;
  std::uint32_t source_width;
  std::uint32_t target_width;
  std::uint32_t target_height;
  std::uint32_t subsample;
  std::uint32_t use_normals;
  std::uint32_t search_radius;
};

bool normal_gate_on(const AssociationParams& params) {
  return params.max_normal_angle_deg < 180.0;
}

// R (row-major), t, fx, fy, cx, cy, max distance^2, min normal cosine.
Frame frame_values(const Eigen::Isometry3d& pose, const PinholeIntrinsics& camera,
                   const AssociationParams& params) {
  std::array<double, kFrameValues> values{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) values[3 * r + c] = pose.linear()(r, c);
    values[9 + r] = pose.translation()(r);
  }
  values[12] = camera.fx;
  values[13] = camera.fy;
  values[14] = camera.cx;
  values[15] = camera.cy;
  values[16] = params.max_distance * params.max_distance;
  values[17] = std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
  Frame frame{};
  for (std::size_t k = 0; k < kFrameValues; ++k) frame[k] = static_cast<float>(values[k]);
  return frame;
}

struct Vec3 {
  float x, y, z;
};

// Products and sums in the kernels' order (no FMA: -std=c++20 implies -ffp-contract=off).
Vec3 rotate(const Frame& f, float x, float y, float z) {
  return {f[0] * x + f[1] * y + f[2] * z, f[3] * x + f[4] * y + f[5] * z,
          f[6] * x + f[7] * y + f[8] * z};
}

// The kernel's rules for one selected source point, in the kernel's order of operations.
std::int32_t associate(const Frame& f, const Point4f& p, const Point4f* source_normal,
                       const Point4f* target, const Point4f* target_normals, int width, int height,
                       int radius) {
  if (!is_valid(p)) return kNoMatch;
  const Vec3 r = rotate(f, p.x(), p.y(), p.z());
  const Vec3 moved{r.x + f[9], r.y + f[10], r.z + f[11]};
  if (!(moved.z > 0.0f)) return kNoMatch;
  const float u = std::floor(f[12] * moved.x / moved.z + f[14] + 0.5f);
  const float v = std::floor(f[13] * moved.y / moved.z + f[15] + 0.5f);
  if (!(u >= static_cast<float>(-radius) && v >= static_cast<float>(-radius) &&
        u < static_cast<float>(width + radius) && v < static_cast<float>(height + radius))) {
    return kNoMatch;
  }
  Vec3 rotated_normal{0.0f, 0.0f, 0.0f};
  if (source_normal) {
    if (!is_valid(*source_normal)) return kNoMatch;
    rotated_normal = rotate(f, source_normal->x(), source_normal->y(), source_normal->z());
  }
  std::int32_t best = kNoMatch;
  float best_distance_sq = f[16];  // max distance^2: farther candidates never win
  const int column = static_cast<int>(u), row = static_cast<int>(v);
  for (int y = std::max(0, row - radius); y <= std::min(height - 1, row + radius); ++y) {
    for (int x = std::max(0, column - radius); x <= std::min(width - 1, column + radius); ++x) {
      const std::size_t j = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                            static_cast<std::size_t>(x);
      const Point4f& q = target[j];
      if (!is_valid(q)) continue;
      const float dx = moved.x - q.x(), dy = moved.y - q.y(), dz = moved.z - q.z();
      const float distance_sq = dx * dx + dy * dy + dz * dz;
      if (!(distance_sq <= best_distance_sq) || (best >= 0 && distance_sq == best_distance_sq)) {
        continue;
      }
      if (source_normal) {
        const Point4f& nq = target_normals[j];
        const float cosine =
            rotated_normal.x * nq.x() + rotated_normal.y * nq.y() + rotated_normal.z * nq.z();
        if (!is_valid(nq) || !(cosine >= f[17])) continue;
      }
      best = static_cast<std::int32_t>(j);
      best_distance_sq = distance_sq;
    }
  }
  return best;
}

// Walks the selected points row by row (no modulo per point), as is_selected() defines them;
// chunks of rows run in parallel (each writes its own entries).
void associate_cpu(const Frame& frame, const CloudView& source, const CloudView& target,
                   bool use_normals, std::uint32_t k, int radius, std::int32_t* out) {
  const Point4f* points = source.points->host_span().data();
  const Point4f* source_normals = use_normals ? source.normals->host_span().data() : nullptr;
  const Point4f* target_points = target.points->host_span().data();
  const Point4f* target_normals = use_normals ? target.normals->host_span().data() : nullptr;
  const std::size_t count = source.size();
  const std::size_t row_length =
      source.camera ? static_cast<std::size_t>(source.camera->width) : count;
  const std::size_t rows = (count + row_length - 1) / row_length;
  compute::detail::for_each_chunk(rows, count, [&](std::size_t first_row, std::size_t end_row, std::size_t) {
    for (std::size_t row = first_row; row < end_row; ++row) {
      const std::size_t start = row * row_length;
      const std::size_t end = std::min(count, start + row_length);
      std::fill(out + start, out + end, kNotSelected);
      for (std::size_t i = start + (k - (start + row) % k) % k; i < end; i += k) {
        out[i] =
            associate(frame, points[i], use_normals ? &source_normals[i] : nullptr, target_points,
                      target_normals, target.camera->width, target.camera->height, radius);
      }
    }
  });
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
  if (!context.is_cpu()) frame_ = compute::Buffer<float>(context, kFrameValues);
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
  if (context_->is_cpu()) {
    associate_cpu(frame, source, target, use_normals, k, params.search_radius,
                  out.target_index.host_span().data());
    return;
  }
  frame_.upload(frame);
  const AssociationKernelParams kernel_params{
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
