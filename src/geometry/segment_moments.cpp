#include "kartograf/geometry/segment_moments.hpp"

#include <cmath>
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

std::int64_t to_fixed(double value, double scale) {
  return static_cast<std::int64_t>(std::nearbyint(value * scale));
}

struct Accumulation {
  std::vector<std::int64_t> moments;
  std::uint32_t points_too_far = 0;
  std::uint32_t bad_labels = 0;
};

void accumulate_cpu(std::span<const Point4f> points, std::span<const std::uint32_t> labels,
                    const SegmentMomentKernelParams& params, Accumulation& out) {
  const double s1 = params.first_scale, s2 = params.second_scale;
  const double bound = params.max_offset;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint32_t label = labels[i];
    const Point4f& p = points[i];
    if (label == kNoLabel || !is_valid(p)) continue;
    if (label >= params.label_count) {
      ++out.bad_labels;
      continue;
    }
    const double dx = static_cast<double>(p.x()) - static_cast<double>(params.origin_x);
    const double dy = static_cast<double>(p.y()) - static_cast<double>(params.origin_y);
    const double dz = static_cast<double>(p.z()) - static_cast<double>(params.origin_z);
    if (std::fabs(dx) > bound || std::fabs(dy) > bound || std::fabs(dz) > bound) {
      ++out.points_too_far;
      continue;
    }
    std::int64_t* m = &out.moments[std::size_t{label} * kValuesPerLabel];
    m[0] += 1;
    m[1] += to_fixed(dx, s1);
    m[2] += to_fixed(dy, s1);
    m[3] += to_fixed(dz, s1);
    m[4] += to_fixed(dx * dx, s2);
    m[5] += to_fixed(dx * dy, s2);
    m[6] += to_fixed(dx * dz, s2);
    m[7] += to_fixed(dy * dy, s2);
    m[8] += to_fixed(dy * dz, s2);
    m[9] += to_fixed(dz * dz, s2);
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

SegmentMomentSet SegmentMomentReducer::run(const compute::Buffer<Point4f>& points,
                                           const compute::Buffer<std::uint32_t>& labels,
                                           const SegmentMomentParams& params) {
  const compute::Context& context = *context_;
  require(params.label_count >= 1 && params.label_count <= kMaxSegmentLabels,
          "segment moments: label_count must be 1.." + std::to_string(kMaxSegmentLabels) + ", got " +
              std::to_string(params.label_count));
  require(points.size() == labels.size(), "segment moments: " + std::to_string(points.size()) +
                                              " points but " + std::to_string(labels.size()) +
                                              " labels");
  require(points.size() < (std::size_t{1} << 31), "segment moments: more than 2^31 points");
  require(params.origin.allFinite(), "segment moments: origin has NaN/Inf");
  require(std::isfinite(params.max_offset) && params.max_offset > 0,
          "segment moments: max_offset must be positive");

  const double count = static_cast<double>(points.size());
  const double bound = params.max_offset;
  const SegmentMomentKernelParams kernel_params{
      static_cast<std::uint32_t>(points.size()), params.label_count, params.origin.x(),
      params.origin.y(),  params.origin.z(),     params.max_offset,
      fixed_point_scale(count, bound), fixed_point_scale(count, bound * bound)};

  Accumulation accumulation;
  accumulation.moments.assign(std::size_t{params.label_count} * kValuesPerLabel, 0);
  if (context.is_cpu()) {
    accumulate_cpu(points.host_span(), labels.host_span(), kernel_params, accumulation);
  } else {
    if (moments_.size() < accumulation.moments.size()) {
      moments_ = compute::Buffer<std::int64_t>(context, accumulation.moments.size());
    }
    moments_.fill_zero();
    status_.fill_zero();
    compute::dispatch(context, kSegmentMomentsKernel, {points, labels, moments_, status_}, kernel_params,
                      {compute::groups_for(points.size(), kSegmentMomentsKernel.local_x), 1});
    moments_.download(std::span<std::int64_t>(accumulation.moments));
    std::uint32_t counters[2] = {};
    status_.download(counters);
    accumulation.points_too_far = counters[0];
    accumulation.bad_labels = counters[1];
  }
  require(accumulation.bad_labels == 0,
          "segment moments: " + std::to_string(accumulation.bad_labels) + " pixels carry a label >= " +
              std::to_string(params.label_count) + " (and not kNoLabel)");
  require(accumulation.points_too_far == 0,
          "segment moments: " + std::to_string(accumulation.points_too_far) +
              " points lie farther than max_offset = " + std::to_string(params.max_offset) +
              " m from the origin");

  SegmentMomentSet result;
  result.origin = params.origin.cast<double>();
  result.segments.resize(params.label_count);
  const double s1 = kernel_params.first_scale, s2 = kernel_params.second_scale;
  for (std::size_t label = 0; label < params.label_count; ++label) {
    const std::int64_t* m = &accumulation.moments[label * kValuesPerLabel];
    SegmentMoments& out = result.segments[label];
    out.count = static_cast<std::uint64_t>(m[0]);
    out.sum = Eigen::Vector3d(m[1] / s1, m[2] / s1, m[3] / s1);
    out.sum_outer << m[4] / s2, m[5] / s2, m[6] / s2,  //
        m[5] / s2, m[7] / s2, m[8] / s2,               //
        m[6] / s2, m[8] / s2, m[9] / s2;
  }
  return result;
}

}  // namespace kartograf::geometry
