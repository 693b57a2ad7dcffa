#include "kartograf/segmentation/clustering_features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "compute/cpu_parallel.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/geometry/segment_moments.hpp"

namespace kartograf::segmentation {
namespace {

static_assert(detail::kChunks == compute::detail::kCpuChunks);

// Rows per distance block: the block's k distances per row stay in cache (256 x 90 doubles).
constexpr Eigen::Index kBlockRows = 256;

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

bool has_point(const Point4f& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

std::array<double, kFeatureDims> raw_feature(const Point4f& p, const Rgb8& c) {
  return {p.x(),
          p.y(),
          p.z(),
          static_cast<double>(c[0]),
          static_cast<double>(c[1]),
          static_cast<double>(c[2])};
}

void check_frame(const char* where, const PointImage& points, const RgbImage& rgb) {
  require(points.width() == rgb.width() && points.height() == rgb.height(),
          std::string(where) + ": the point image (" + size_text(points.width(), points.height()) +
              ") and the colour image (" + size_text(rgb.width(), rgb.height()) +
              ") differ in size");
  require(!points.empty(), std::string(where) + ": empty frame (0 pixels)");
}

FeatureScaling scaling_of(const PointImage& points, const RgbImage& rgb, double weight) {
  std::array<double, kFeatureDims> low, high;
  low.fill(std::numeric_limits<double>::infinity());
  high.fill(-std::numeric_limits<double>::infinity());
  std::size_t valid = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!has_point(points.data()[i])) continue;
    ++valid;
    const auto raw = raw_feature(points.data()[i], rgb.data()[i]);
    for (int c = 0; c < kFeatureDims; ++c) {
      low[c] = std::min(low[c], raw[c]);
      high[c] = std::max(high[c], raw[c]);
    }
  }
  require(valid > 0, "make_clustering_features: no valid pixel in the " +
                         size_text(points.width(), points.height()) +
                         " frame (every point is NaN or infinite)");
  FeatureScaling scaling;
  for (int c = 0; c < kFeatureDims; ++c) {
    const double column_weight = c < 3 ? weight : 1.0;
    scaling.offset[c] = low[c];
    scaling.scale[c] = high[c] > low[c] ? column_weight / (high[c] - low[c]) : 0.0;
  }
  return scaling;
}

// Rows for the valid pixels with x % stride == 0 and y % stride == 0, in row-major order.
void fill_rows(const PointImage& points, const RgbImage& rgb, int stride,
               ClusteringFeatures& features) {
  const auto for_each_pixel = [&](auto&& body) {
    for (int y = 0; y < points.height(); y += stride)
      for (int x = 0; x < points.width(); x += stride)
        if (has_point(points(x, y))) body(x, y);
  };
  std::size_t count = 0;
  for_each_pixel([&](int, int) { ++count; });
  features.width = points.width();
  features.height = points.height();
  features.values.resize(static_cast<Eigen::Index>(count), kFeatureDims);
  features.pixels.clear();
  features.pixels.reserve(count);
  for_each_pixel([&](int x, int y) {
    const auto raw = raw_feature(points(x, y), rgb(x, y));
    const auto row = static_cast<Eigen::Index>(features.pixels.size());
    for (int c = 0; c < kFeatureDims; ++c)
      features.values(row, c) =
          static_cast<float>((raw[c] - features.scaling.offset[c]) * features.scaling.scale[c]);
    features.pixels.push_back(static_cast<std::uint32_t>(y) *
                                  static_cast<std::uint32_t>(points.width()) +
                              static_cast<std::uint32_t>(x));
  });
}

void check_result(const char* where, const ClusteringFeatures& features,
                  const ClusteringResult& result) {
  require(result.labels.size() == features.size(),
          std::string(where) + ": the result has " + std::to_string(result.labels.size()) +
              " labels for " + std::to_string(features.size()) + " features");
  require(result.centres.rows() > 0, std::string(where) + ": the result has no centres");
}

}  // namespace

ClusteringFeatures make_clustering_features(const PointImage& points, const RgbImage& rgb,
                                            const FeatureParams& params) {
  check_frame("make_clustering_features", points, rgb);
  require(std::isfinite(params.geometric_weight) && params.geometric_weight > 0,
          "make_clustering_features: geometric_weight = " +
              std::to_string(params.geometric_weight) + "; expected a finite value > 0");
  require(params.stride >= 1, "make_clustering_features: stride = " +
                                  std::to_string(params.stride) + "; expected >= 1");
  ClusteringFeatures features;
  features.scaling = scaling_of(points, rgb, params.geometric_weight);
  fill_rows(points, rgb, params.stride, features);
  return features;
}

double quantisation_error(const ClusteringFeatures& features, const ClusteringResult& result) {
  check_result("quantisation_error", features, result);
  double sum = 0;
  for (std::size_t i = 0; i < features.size(); ++i) {
    const std::uint32_t label = result.labels[i];
    require(label < result.centres.rows(), "quantisation_error: feature " + std::to_string(i) +
                                               " has label " + std::to_string(label) +
                                               " beyond the " +
                                               std::to_string(result.centres.rows()) + " centres");
    sum += (features.values.row(static_cast<Eigen::Index>(i)).cast<double>() -
            result.centres.row(label))
               .squaredNorm();
  }
  return sum / static_cast<double>(features.size());
}

SegmentLabelImage label_image(const ClusteringFeatures& features, const ClusteringResult& result) {
  check_result("label_image", features, result);
  SegmentLabelImage labels(features.width, features.height, geometry::kNoLabel);
  for (std::size_t i = 0; i < features.size(); ++i) {
    require(features.pixels[i] < labels.size(),
            "label_image: feature " + std::to_string(i) + " names pixel " +
                std::to_string(features.pixels[i]) + " outside the " +
                size_text(features.width, features.height) + " frame");
    labels.data()[features.pixels[i]] = result.labels[i];
  }
  return labels;
}

SegmentLabelImage label_all_pixels(const PointImage& points, const RgbImage& rgb,
                                   const ClusteringFeatures& features,
                                   const ClusteringResult& result) {
  check_frame("label_all_pixels", points, rgb);
  require(points.width() == features.width && points.height() == features.height,
          "label_all_pixels: the frame (" + size_text(points.width(), points.height()) +
              ") is not the one the features came from (" +
              size_text(features.width, features.height) + ")");
  check_result("label_all_pixels", features, result);
  ClusteringFeatures all;
  all.scaling = features.scaling;
  fill_rows(points, rgb, 1, all);
  const NearestCentres nearest = nearest_centres(all.values, result.centres);
  SegmentLabelImage labels(points.width(), points.height(), geometry::kNoLabel);
  for (std::size_t i = 0; i < all.size(); ++i) labels.data()[all.pixels[i]] = nearest.labels[i];
  return labels;
}

NearestCentres nearest_centres(const FeatureMatrix& features, const CentreMatrix& centres) {
  require(centres.rows() > 0, "nearest_centres: no centres");
  NearestCentres nearest;
  nearest.labels.resize(static_cast<std::size_t>(features.rows()));
  nearest.squared_distances.resize(nearest.labels.size());
  detail::for_each_distance_block(
      features, centres,
      [&](std::size_t, Eigen::Index first, const Eigen::MatrixXd&, const Eigen::MatrixXd& d) {
        for (Eigen::Index r = 0; r < d.rows(); ++r) {
          Eigen::Index best = 0;
          d.row(r).minCoeff(&best);  // the first minimum: lowest index among equals
          const auto row = static_cast<std::size_t>(first + r);
          nearest.labels[row] = static_cast<std::uint32_t>(best);
          nearest.squared_distances[row] = d(r, best);
        }
      });
  return nearest;
}

namespace detail {

void for_each_distance_block(const FeatureMatrix& features, const CentreMatrix& centres,
                             const DistanceBlockVisitor& visit) {
  const Eigen::MatrixXd centres_t = centres.transpose();
  const Eigen::RowVectorXd centre_norms = centres.rowwise().squaredNorm().transpose();
  const auto rows = static_cast<std::size_t>(features.rows());
  compute::detail::for_each_chunk(
      rows, rows * static_cast<std::size_t>(centres.rows()),
      [&](std::size_t begin, std::size_t end, std::size_t chunk) {
        Eigen::MatrixXd block, distances;
        for (auto first = static_cast<Eigen::Index>(begin); first < static_cast<Eigen::Index>(end);
             first += kBlockRows) {
          const Eigen::Index count = std::min(kBlockRows, static_cast<Eigen::Index>(end) - first);
          block = features.middleRows(first, count).cast<double>();
          // |x - c|^2 = |x|^2 - 2 x.c + |c|^2 as one matrix product; in double the cancellation
          // costs ~1e-15 of |x|^2, and clamping keeps coinciding points at 0.
          distances.noalias() = -2.0 * block * centres_t;
          distances.rowwise() += centre_norms;
          distances.colwise() += block.rowwise().squaredNorm();
          distances = distances.cwiseMax(0.0);
          visit(chunk, first, block, distances);
        }
      });
}

void check_cluster_count(const char* method, std::uint32_t k, const ClusteringFeatures& features) {
  const std::string name(method);
  require(features.values.rows() == static_cast<Eigen::Index>(features.pixels.size()),
          name + ": the features have " + std::to_string(features.values.rows()) + " rows but " +
              std::to_string(features.pixels.size()) + " pixel indices");
  require(features.size() > 0, name + ": no features to cluster (the frame has no valid pixel)");
  require(k >= 1, name + ": k = 0 clusters; expected 1.." + std::to_string(features.size()));
  require(k <= features.size(), name + ": k = " + std::to_string(k) + " clusters exceeds the " +
                                    std::to_string(features.size()) + " features to cluster");
}

void check_iterations(const char* method, int max_iterations, double tolerance) {
  const std::string name(method);
  require(max_iterations >= 1,
          name + ": max_iterations = " + std::to_string(max_iterations) + "; expected >= 1");
  require(std::isfinite(tolerance) && tolerance >= 0,
          name + ": tolerance = " + std::to_string(tolerance) + "; expected a finite value >= 0");
}

}  // namespace detail
}  // namespace kartograf::segmentation
