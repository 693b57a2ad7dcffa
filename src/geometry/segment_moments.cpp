#include "kartograf/geometry/segment_moments.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/compute/kernel.hpp"
#include "kernels/segment_moments/segment_moments_cpu.hpp"

namespace kartograf::geometry {

namespace {

constexpr compute::KernelSpec kSegmentMomentsKernel{"segment_moments", KG_SEGMENT_MOMENTS_LOCAL_X};
constexpr std::size_t kValuesPerLabel = KG_SEGMENT_MOMENT_VALUES;
static_assert(std::tuple_size_v<FixedPointMoments::Sums> == kValuesPerLabel);

// The largest power of two s with max_total * s < 2^62: no sum of up to `count` terms of
// magnitude <= per_term can overflow int64.
float fixed_point_scale(double count, double per_term) {
  const double max_total = std::max(1.0, count * per_term);
  return static_cast<float>(std::exp2(std::floor(62.0 - std::log2(max_total))));
}

struct Accumulation {
  std::vector<std::int64_t> sums;  // kValuesPerLabel per label
  std::uint32_t status[2] = {};    // indexed by KG_SEGMENT_MOMENTS_*
};

}  // namespace

Eigen::Vector3d SegmentMomentSet::centroid(std::uint32_t label) const {
  const SegmentMoments& m = segments.at(label);
  return m.count == 0 ? origin : Eigen::Vector3d(origin + m.sum / static_cast<double>(m.count));
}

Eigen::Matrix3d SegmentMomentSet::covariance(std::uint32_t label) const {
  const SegmentMoments& m = segments.at(label);
  if (m.count == 0) return Eigen::Matrix3d::Zero();
  const double n = static_cast<double>(m.count);
  const Eigen::Vector3d mean = m.sum / n;
  return m.sum_outer / n - mean * mean.transpose();
}

SegmentMomentReducer::SegmentMomentReducer(const compute::Context& context)
    : context_(&context), status_(context, 2) {}

SegmentMomentSet segment_moments(const compute::Context& context,
                                 const compute::Buffer<Point4f>& points,
                                 const compute::Buffer<std::uint32_t>& labels,
                                 const SegmentMomentParams& params) {
  return SegmentMomentReducer(context).run(points, labels, params);
}

namespace {

void check_params(std::size_t point_count, std::size_t label_length,
                  const SegmentMomentParams& params, std::uint32_t max_labels) {
  require(params.label_count >= 1 && params.label_count <= max_labels,
          "segment moments: label_count must be 1.." + std::to_string(max_labels) + ", got " +
              std::to_string(params.label_count));
  require(point_count == label_length, "segment moments: " + std::to_string(point_count) +
                                           " points but " + std::to_string(label_length) +
                                           " labels");
  require(point_count < (std::size_t{1} << 31), "segment moments: more than 2^31 points");
  require(params.origin.allFinite(), "segment moments: origin has NaN/Inf");
  require(std::isfinite(params.max_offset) && params.max_offset > 0,
          "segment moments: max_offset must be positive");
}

kernels::SegmentMomentsParams kernel_params_for(std::size_t point_count,
                                                const SegmentMomentParams& params,
                                                const FixedPointMoments& fixed) {
  return {static_cast<std::uint32_t>(point_count),
          params.label_count,
          params.origin.x(),
          params.origin.y(),
          params.origin.z(),
          params.max_offset,
          fixed.first_scale(),
          fixed.second_scale()};
}

// Checks the counters and turns the fixed-point sums into moments.
SegmentMomentSet finish(const Accumulation& accumulation, const SegmentMomentParams& params,
                        const FixedPointMoments& fixed) {
  const std::uint32_t bad_labels = accumulation.status[KG_SEGMENT_MOMENTS_BAD_LABEL];
  const std::uint32_t points_too_far = accumulation.status[KG_SEGMENT_MOMENTS_TOO_FAR];
  require(bad_labels == 0, "segment moments: " + std::to_string(bad_labels) +
                               " pixels carry a label >= " + std::to_string(params.label_count) +
                               " (and not kNoLabel)");
  require(points_too_far == 0, "segment moments: " + std::to_string(points_too_far) +
                                   " points lie farther than max_offset = " +
                                   std::to_string(params.max_offset) + " m from the origin");
  SegmentMomentSet result;
  result.origin = params.origin.cast<double>();
  result.segments.resize(params.label_count);
  FixedPointMoments::Sums sums;
  for (std::size_t label = 0; label < params.label_count; ++label) {
    std::copy_n(&accumulation.sums[label * kValuesPerLabel], kValuesPerLabel, sums.begin());
    result.segments[label] = fixed.moments(sums);
  }
  return result;
}

}  // namespace

FixedPointMoments::FixedPointMoments(std::size_t point_count, const SegmentMomentParams& params)
    : first_scale_(fixed_point_scale(static_cast<double>(point_count), params.max_offset)),
      second_scale_(fixed_point_scale(static_cast<double>(point_count),
                                      double{params.max_offset} * params.max_offset)) {}

SegmentMoments FixedPointMoments::moments(const Sums& m) const {
  const double s1 = first_scale_, s2 = second_scale_;
  SegmentMoments out;
  out.count = static_cast<std::uint64_t>(m[0]);
  out.sum = Eigen::Vector3d(m[1] / s1, m[2] / s1, m[3] / s1);
  out.sum_outer << m[4] / s2, m[5] / s2, m[6] / s2,  //
      m[5] / s2, m[7] / s2, m[8] / s2,               //
      m[6] / s2, m[8] / s2, m[9] / s2;
  return out;
}

SegmentMomentSet segment_moments(std::span<const Point4f> points,
                                 std::span<const std::uint32_t> labels,
                                 const SegmentMomentParams& params) {
  check_params(points.size(), labels.size(), params, std::numeric_limits<std::uint32_t>::max() - 1);
  const FixedPointMoments fixed(points.size(), params);
  Accumulation accumulation;
  accumulation.sums.assign(std::size_t{params.label_count} * kValuesPerLabel, 0);
  kernels::accumulate_segment_moments(reinterpret_cast<const kernels::float4*>(points.data()),
                                      labels.data(),
                                      kernel_params_for(points.size(), params, fixed),
                                      accumulation.sums.data(), accumulation.status);
  return finish(accumulation, params, fixed);
}

SegmentMomentSet SegmentMomentReducer::run(const compute::Buffer<Point4f>& points,
                                           const compute::Buffer<std::uint32_t>& labels,
                                           const SegmentMomentParams& params) {
  const compute::Context& context = *context_;
  check_params(points.size(), labels.size(), params, kMaxSegmentLabels);
  const FixedPointMoments fixed(points.size(), params);
  const std::size_t values = std::size_t{params.label_count} * kValuesPerLabel;
  if (moments_.size() < values) moments_ = compute::Buffer<std::int64_t>(context, values);
  moments_.fill_zero();
  status_.fill_zero();
  compute::dispatch(context, kSegmentMomentsKernel, {points, labels, moments_, status_},
                    kernel_params_for(points.size(), params, fixed),
                    {compute::groups_for(points.size(), kSegmentMomentsKernel.local_x), 1});
  Accumulation accumulation;
  accumulation.sums.resize(values);
  moments_.download(std::span<std::int64_t>(accumulation.sums));
  status_.download(accumulation.status);
  return finish(accumulation, params, fixed);
}

}  // namespace kartograf::geometry
