#include "kartograf/rooms/laser_features.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/geometry/distance_transform.hpp"
#include "kernels/laser_scan/laser_scan.h"

namespace kartograf::rooms {

namespace {

// Feature indices, in the order of laser_feature_names().
enum Feature : std::size_t {
  mean_difference,
  std_difference,
  mean_clipped_difference,
  std_clipped_difference,
  mean_beam,
  std_beam,
  gaps,
  minima_distance,
  minima_angle,
  mean_ratio,
  std_ratio,
  relative_gaps,
  beam_kurtosis,
  polygon_area,
  polygon_perimeter,
  area_per_perimeter,
  mean_centroid_distance,
  std_centroid_distance,
  major_semi_axis,
  minor_semi_axis,
  axis_ratio,
  mean_beam_per_max,
  std_beam_per_max,
  compactness,
  shortest_beam,
  longest_beam,
  centroid_offset
};

struct MeanStd {
  double mean = 0, std = 0;
};

// Population mean and standard deviation from the sum and the sum of squares of n values.
MeanStd from_sums(double sum, double sum2, std::size_t n) {
  const double mean = sum / static_cast<double>(n);
  return {mean, std::sqrt(std::max(0.0, sum2 / static_cast<double>(n) - mean * mean))};
}

// Population mean and standard deviation of f(i), i in [0, n).
template <class F>
MeanStd mean_std(std::size_t n, F&& f) {
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = f(i);
    sum += v;
    sum2 += v * v;
  }
  return from_sums(sum, sum2, n);
}

double norm(double x, double y) {
  return std::sqrt(x * x + y * y);
}

// Unit vectors of n beams at equal angles (cached: every scan of a map has the same n).
void unit_directions(std::size_t n, std::vector<double>& xs, std::vector<double>& ys) {
  thread_local std::vector<double> cos_table, sin_table;
  if (cos_table.size() != n) {
    cos_table.resize(n);
    sin_table.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double angle = 2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
      cos_table[k] = std::cos(angle);
      sin_table[k] = std::sin(angle);
    }
  }
  xs = cos_table;
  ys = sin_table;
}

void set(LaserFeatures& f, Feature which, double value) {
  f[which] = static_cast<float>(value);
}

// Differences and ratios of consecutive beams (cyclic: the last beam is followed by the first).
void set_consecutive_beam_features(std::span<const double> ranges, const LaserFeatureParams& params,
                                   LaserFeatures& f) {
  const std::size_t n = ranges.size();
  const auto next = [&](std::size_t i) { return i + 1 < n ? ranges[i + 1] : ranges[0]; };
  double sum_difference = 0, sum2_difference = 0, sum_clipped = 0, sum2_clipped = 0;
  double sum_ratio = 0, sum2_ratio = 0;
  int gap_count = 0, relative_gap_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = ranges[i], b = next(i);
    const double difference = std::abs(a - b);
    const double clipped = std::abs(std::min(a, params.clip_m) - std::min(b, params.clip_m));
    const double ratio = std::min(a, b) / std::max(a, b);
    sum_difference += difference;
    sum2_difference += difference * difference;
    sum_clipped += clipped;
    sum2_clipped += clipped * clipped;
    sum_ratio += ratio;
    sum2_ratio += ratio * ratio;
    gap_count += difference > params.gap_m;
    relative_gap_count += ratio < params.relative_gap;
  }
  const MeanStd difference = from_sums(sum_difference, sum2_difference, n);
  const MeanStd clipped = from_sums(sum_clipped, sum2_clipped, n);
  const MeanStd ratio = from_sums(sum_ratio, sum2_ratio, n);
  set(f, mean_difference, difference.mean);
  set(f, std_difference, difference.std);
  set(f, mean_clipped_difference, clipped.mean);
  set(f, std_clipped_difference, clipped.std);
  set(f, gaps, gap_count);
  set(f, mean_ratio, ratio.mean);
  set(f, std_ratio, ratio.std);
  set(f, relative_gaps, relative_gap_count);
}

// Beam lengths: their mean, spread, kurtosis and extremes.
void set_beam_length_features(std::span<const double> ranges, LaserFeatures& f) {
  const std::size_t n = ranges.size();
  const MeanStd length = mean_std(n, [&](std::size_t i) { return ranges[i]; });
  const auto [shortest, longest] = std::minmax_element(ranges.begin(), ranges.end());
  double m4 = 0;
  for (const double b : ranges) {
    const double d2 = (b - length.mean) * (b - length.mean);
    m4 += d2 * d2;
  }
  m4 /= static_cast<double>(n);
  const double variance = length.std * length.std;
  set(f, mean_beam, length.mean);
  set(f, std_beam, length.std);
  set(f, beam_kurtosis, variance > 1e-12 ? m4 / (variance * variance) - 3 : 0.0);
  set(f, mean_beam_per_max, length.mean / *longest);
  set(f, std_beam_per_max, length.std / *longest);
  set(f, shortest_beam, *shortest);
  set(f, longest_beam, *longest);
}

// The shortest beam and the shortest one at least a quarter turn away from it: in a corridor,
// the two walls; their end points' distance is its width.
void set_minima_features(std::span<const double> ranges, LaserFeatures& f) {
  const std::size_t n = ranges.size();
  const double step = 2 * std::numbers::pi / static_cast<double>(n);
  // The first shortest beam, as std::minmax_element finds it.
  const std::size_t first =
      static_cast<std::size_t>(std::min_element(ranges.begin(), ranges.end()) - ranges.begin());
  std::size_t second = first;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t apart = std::min((i + n - first) % n, (first + n - i) % n);
    if (4 * apart >= n && (second == first || ranges[i] < ranges[second])) second = i;
  }
  const std::size_t apart = std::min((second + n - first) % n, (first + n - second) % n);
  const double angle = static_cast<double>(apart) * step;
  const double b1 = ranges[first], b2 = ranges[second];
  set(f, minima_distance,
      std::sqrt(std::max(0.0, b1 * b1 + b2 * b2 - 2 * b1 * b2 * std::cos(angle))));
  set(f, minima_angle, angle * 180 / std::numbers::pi);
}

// The polygon of the beams' end points: area, perimeter, centroid and second moments.
void set_polygon_features(std::span<const double> ranges, LaserFeatures& f) {
  const std::size_t n = ranges.size();
  thread_local std::vector<double> xs, ys;
  unit_directions(n, xs, ys);
  for (std::size_t i = 0; i < n; ++i) {
    xs[i] *= ranges[i];
    ys[i] *= ranges[i];
  }
  double area2 = 0, perimeter = 0, cx6 = 0, cy6 = 0, ixx12 = 0, iyy12 = 0, ixy24 = 0;
  double vx = 0, vy = 0;  // vertex mean
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const double x0 = xs[i], y0 = ys[i], x1 = xs[j], y1 = ys[j];
    const double cross = x0 * y1 - x1 * y0;
    area2 += cross;
    perimeter += norm(x1 - x0, y1 - y0);
    cx6 += (x0 + x1) * cross;
    cy6 += (y0 + y1) * cross;
    ixx12 += (x0 * x0 + x0 * x1 + x1 * x1) * cross;
    iyy12 += (y0 * y0 + y0 * y1 + y1 * y1) * cross;
    ixy24 += (x0 * y1 + 2 * x0 * y0 + 2 * x1 * y1 + x1 * y0) * cross;
    vx += x0;
    vy += y0;
  }
  const double area = area2 / 2;  // > 0: the beams turn counter-clockwise
  const double cx = cx6 / (6 * area), cy = cy6 / (6 * area);
  const double sxx = ixx12 / (12 * area) - cx * cx, syy = iyy12 / (12 * area) - cy * cy;
  const double sxy = ixy24 / (24 * area) - cx * cy;
  // Eigenvalues of the area's covariance; a uniform ellipse with semi-axis a has variance a^2/4.
  const double half_trace = (sxx + syy) / 2;
  const double root = std::sqrt(std::max(0.0, (sxx - syy) * (sxx - syy) / 4 + sxy * sxy));
  const double major = 2 * std::sqrt(std::max(0.0, half_trace + root));
  const double minor = 2 * std::sqrt(std::max(0.0, half_trace - root));
  vx /= static_cast<double>(n);
  vy /= static_cast<double>(n);
  const MeanStd centroid_distance =
      mean_std(n, [&](std::size_t i) { return norm(xs[i] - vx, ys[i] - vy); });
  set(f, polygon_area, area);
  set(f, polygon_perimeter, perimeter);
  set(f, area_per_perimeter, area / perimeter);
  set(f, mean_centroid_distance, centroid_distance.mean);
  set(f, std_centroid_distance, centroid_distance.std);
  set(f, major_semi_axis, major);
  set(f, minor_semi_axis, minor);
  set(f, axis_ratio, major / std::max(minor, 1e-6));
  set(f, compactness, 4 * std::numbers::pi * area / (perimeter * perimeter));
  set(f, centroid_offset, norm(cx, cy));
}
}  // namespace

LaserScanner::LaserScanner(const OccupancyGrid& map, const LaserScanParams& params)
    : width_(map.width()), height_(map.height()), resolution_(map.resolution) {
  require(width_ > 0 && height_ > 0, "laser scanner: the map has no cells");
  require(width_ <= kMaxLaserScanMapSide && height_ <= kMaxLaserScanMapSide,
          "laser scanner: the map is " + std::to_string(width_) + " x " + std::to_string(height_) +
              " cells; at most " + std::to_string(kMaxLaserScanMapSide) + " per side");
  require(resolution_ > 0 && std::isfinite(resolution_),
          "laser scanner: the map resolution must be > 0, got " + std::to_string(resolution_));
  require(params.beams >= 8,
          "laser scanner: beams must be >= 8, got " + std::to_string(params.beams));
  require(params.max_range_m > 0 && std::isfinite(params.max_range_m),
          "laser scanner: max_range_m must be > 0, got " + std::to_string(params.max_range_m));
  // Every beam stops at the border ring within 2^16 steps, so a larger limit changes nothing; the
  // cap keeps step + skip far from overflowing.
  max_steps_ = static_cast<int>(
      std::clamp(std::ceil(params.max_range_m / resolution_), 1.0, double{1 << 24}));
  // Free space with a border of non-free cells, so that the grid's edge stops rays like a wall.
  Image<std::uint8_t> free(width_ + 2, height_ + 2, 0);
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x)
      free(x + 1, y + 1) = map.cells(x, y) == CellState::free ? 255 : 0;
  }
  const Image<float> distance = geometry::distance_to_zero(free);
  // A skip of s steps moves a sample by s |direction| <= s (1 + 1.1e-5) cells (rounded directions);
  // from within 0.71 cells of a free cell centre at distance d >= s + 1.5 from every non-free
  // centre, the sample's cell centre stays closer than d while s * 1.1e-5 < 0.085: s <= 4096.
  constexpr int kMaxSkip = 4096;
  skips_ = Image<std::int32_t>(width_ + 2, height_ + 2);
  for (int y = 0; y < height_ + 2; ++y) {
    for (int x = 0; x < width_ + 2; ++x) {
      const float d = distance(x, y);
      skips_(x, y) = d <= 0 ? 0 : std::clamp(static_cast<int>(d - 1.5f), 1, kMaxSkip);
    }
  }
  directions_.resize(2 * static_cast<std::size_t>(params.beams));
  for (int k = 0; k < params.beams; ++k) {
    const double angle = 2 * std::numbers::pi * k / params.beams;
    // Image rows grow downwards, so the map's +y is -row.
    directions_[2 * static_cast<std::size_t>(k)] =
        static_cast<std::int32_t>(std::llround(std::cos(angle) * 65536.0));
    directions_[2 * static_cast<std::size_t>(k) + 1] =
        static_cast<std::int32_t>(std::llround(-std::sin(angle) * 65536.0));
  }
}

void LaserScanner::scan_steps(int col, int row, std::span<std::int32_t> steps) const {
  if (steps.size() != static_cast<std::size_t>(beams())) {
    throw Error("laser scanner: expected room for " + std::to_string(beams()) + " beams, got " +
                std::to_string(steps.size()));
  }
  std::fill(steps.begin(), steps.end(), 0);
  if (col < 0 || row < 0 || col >= width_ || row >= height_) return;
  // The cell centre in the padded grid, 1/65536 cell units (a non-free cell stops at step 0).
  const std::int32_t x0 = kernels::laser_cell_origin(col), y0 = kernels::laser_cell_origin(row);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    steps[k] = kernels::laser_trace_beam(skips_.data(), width_ + 2, x0, y0, directions_[2 * k],
                                         directions_[2 * k + 1], max_steps_);
  }
}

void LaserScanner::scan(int col, int row, std::span<double> ranges) const {
  if (ranges.size() != static_cast<std::size_t>(beams())) {
    throw Error("laser scanner: expected room for " + std::to_string(beams()) + " beams, got " +
                std::to_string(ranges.size()));
  }
  thread_local std::vector<std::int32_t> steps;
  steps.resize(ranges.size());
  scan_steps(col, row, steps);
  for (std::size_t k = 0; k < ranges.size(); ++k) ranges[k] = steps[k] * resolution_;
}

const std::array<std::string_view, kLaserFeatureCount>& laser_feature_names() {
  static const std::array<std::string_view, kLaserFeatureCount> names{"mean_difference",
                                                                      "std_difference",
                                                                      "mean_clipped_difference",
                                                                      "std_clipped_difference",
                                                                      "mean_beam",
                                                                      "std_beam",
                                                                      "gaps",
                                                                      "minima_distance",
                                                                      "minima_angle",
                                                                      "mean_ratio",
                                                                      "std_ratio",
                                                                      "relative_gaps",
                                                                      "beam_kurtosis",
                                                                      "polygon_area",
                                                                      "polygon_perimeter",
                                                                      "area_per_perimeter",
                                                                      "mean_centroid_distance",
                                                                      "std_centroid_distance",
                                                                      "major_semi_axis",
                                                                      "minor_semi_axis",
                                                                      "axis_ratio",
                                                                      "mean_beam_per_max",
                                                                      "std_beam_per_max",
                                                                      "compactness",
                                                                      "shortest_beam",
                                                                      "longest_beam",
                                                                      "centroid_offset"};
  return names;
}

LaserFeatures laser_scan_features(std::span<const double> ranges,
                                  const LaserFeatureParams& params) {
  const std::size_t n = ranges.size();
  require(n >= 8, "laser scan features: need at least 8 beams, got " + std::to_string(n));
  for (const double b : ranges) {
    if (!(b > 0 && std::isfinite(b)))
      throw Error("laser scan features: beam lengths must be > 0 and finite, got " +
                  std::to_string(b));
  }
  LaserFeatures f{};
  set_consecutive_beam_features(ranges, params, f);
  set_beam_length_features(ranges, f);
  set_minima_features(ranges, f);
  set_polygon_features(ranges, f);
  return f;
}

}  // namespace kartograf::rooms
