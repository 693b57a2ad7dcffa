#include "kartograf/geometry/segment_moments.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/compute/kernel.hpp"

namespace kartograf::geometry {

namespace {

constexpr compute::KernelSpec kSegmentMomentsKernel{"segment_moments", 256};
constexpr std::size_t kValuesPerLabel = 10;

struct SegmentMomentKernelParams {  // layout of shaders/segment_moments.comp and the .cl kernel
  std::uint32_t point_count;
  std::uint32_t label_count;
  float origin_x;
  float origin_y;
  float origin_z;
  float max_offset;
  float first_scale;
  float second_scale;
};

// The largest power of two s with max_total * s < 2^62: no sum of up to `count` terms of
// magnitude <= per_term can overflow int64.
float fixed_point_scale(double count, double per_term) {
  const double max_total = std::max(1.0, count * per_term);
  return static_cast<float>(std::exp2(std::floor(62.0 - std::log2(max_total))));
}

struct Accumulation {
  std::vector<FixedPointMoments::Sums> moments;  // per label
  std::uint32_t points_too_far = 0;
  std::uint32_t bad_labels = 0;
};

void accumulate_cpu(std::span<const Point4f> points, std::span<const std::uint32_t> labels,
                    const FixedPointMoments& fixed, std::uint32_t label_count, Accumulation& out) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t label = labels[i];
    const Point4f& p = points[i];
    if (label == kNoLabel || !is_valid(p)) continue;
    if (label >= label_count) {
      ++out.bad_labels;
      continue;
    }
    if (!fixed.add(p, out.moments[label])) ++out.points_too_far;
  }
}

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

SegmentMomentReducer::SegmentMomentReducer(const compute::Context& context) : context_(&context) {
  if (!context.is_cpu()) status_ = compute::Buffer<std::uint32_t>(context, 2);
}

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

SegmentMomentKernelParams kernel_params_for(std::size_t point_count,
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
  require(accumulation.bad_labels == 0,
          "segment moments: " + std::to_string(accumulation.bad_labels) +
              " pixels carry a label >= " + std::to_string(params.label_count) +
              " (and not kNoLabel)");
  require(accumulation.points_too_far == 0,
          "segment moments: " + std::to_string(accumulation.points_too_far) +
              " points lie farther than max_offset = " + std::to_string(params.max_offset) +
              " m from the origin");
  SegmentMomentSet result;
  result.origin = params.origin.cast<double>();
  result.segments.reserve(accumulation.moments.size());
  for (const FixedPointMoments::Sums& sums : accumulation.moments)
    result.segments.push_back(fixed.moments(sums));
  return result;
}

}  // namespace

FixedPointMoments::FixedPointMoments(std::size_t point_count, const SegmentMomentParams& params)
    : origin_(params.origin.cast<double>()),
      bound_(params.max_offset),
      first_scale_(fixed_point_scale(static_cast<double>(point_count), params.max_offset)),
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
  accumulation.moments.assign(params.label_count, FixedPointMoments::Sums{});
  accumulate_cpu(points, labels, fixed, params.label_count, accumulation);
  return finish(accumulation, params, fixed);
}

SegmentMomentSet SegmentMomentReducer::run(const compute::Buffer<Point4f>& points,
                                           const compute::Buffer<std::uint32_t>& labels,
                                           const SegmentMomentParams& params) {
  const compute::Context& context = *context_;
  check_params(points.size(), labels.size(), params, kMaxSegmentLabels);
  if (context.is_cpu()) return segment_moments(points.host_span(), labels.host_span(), params);
  const FixedPointMoments fixed(points.size(), params);
  const std::size_t values = std::size_t{params.label_count} * kValuesPerLabel;
  if (moments_.size() < values) moments_ = compute::Buffer<std::int64_t>(context, values);
  moments_.fill_zero();
  status_.fill_zero();
  compute::dispatch(context, kSegmentMomentsKernel, {points, labels, moments_, status_},
                    kernel_params_for(points.size(), params, fixed),
                    {compute::groups_for(points.size(), kSegmentMomentsKernel.local_x), 1});
  std::vector<std::int64_t> sums(values);
  moments_.download(std::span<std::int64_t>(sums));
  Accumulation accumulation;
  accumulation.moments.resize(params.label_count);
  for (std::size_t label = 0; label < params.label_count; ++label) {
    std::copy_n(&sums[label * kValuesPerLabel], kValuesPerLabel,
                accumulation.moments[label].begin());
  }
  std::uint32_t counters[2] = {};
  status_.download(counters);
  accumulation.points_too_far = counters[0];
  accumulation.bad_labels = counters[1];
  return finish(accumulation, params, fixed);
}

}  // namespace kartograf::geometry
