#pragma once
// The clustering baselines of docs/methods.md M1 step 7 (K-Means, SOM, Fuzzy C-Means) all cluster
// the same 6-D per-pixel features (x, y, z, R, G, B): each column min-max normalised to [0, 1] over
// the frame's valid pixels, the geometric columns then multiplied by a constant weight so that
// position counts more than colour (the paper: "a constant weight greater than one"). This header
// builds those features, holds what every method returns, and turns a result into a label image.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/segmentation/region_growing.hpp"

namespace kartograf::segmentation {

inline constexpr int kFeatureDims = 6;  // x, y, z, R, G, B
// One feature per row; float storage (a 640x480 frame is 7 MB), double arithmetic.
using FeatureMatrix = Eigen::Matrix<float, Eigen::Dynamic, kFeatureDims, Eigen::RowMajor>;
// One cluster centre (K-Means, FCM) or map node (SOM) per row, in feature space.
using CentreMatrix = Eigen::Matrix<double, Eigen::Dynamic, kFeatureDims, Eigen::RowMajor>;

struct FeatureParams {
  // Multiplies the normalised x, y, z columns. The paper gives no value, only "> 1".
  double geometric_weight = 3.0;
  // 1: every valid pixel (the paper); s > 1: the valid pixels with x % s == 0 and y % s == 0, for
  // speed; label_all_pixels then labels the rest of the frame by nearest centre.
  int stride = 1;
};

// feature[c] = (raw[c] - offset[c]) * scale[c], raw = (x, y, z in metres, R, G, B in 0..255);
// scale = weight / (max - min) over the frame's valid pixels (0 for a constant column).
struct FeatureScaling {
  std::array<double, kFeatureDims> offset{};
  std::array<double, kFeatureDims> scale{};
};

struct ClusteringFeatures {
  int width = 0;  // of the frame the features came from
  int height = 0;
  FeatureMatrix values;               // n x 6
  std::vector<std::uint32_t> pixels;  // row i is pixel pixels[i] = y * width + x
  FeatureScaling scaling;
  std::size_t size() const { return pixels.size(); }
};

// Features of the valid pixels (finite point) of one frame, in row-major pixel order. Throws
// Error on a size mismatch, an empty frame, a frame without valid pixels, a non-positive or
// non-finite weight or a stride < 1.
ClusteringFeatures make_clustering_features(const PointImage& points, const RgbImage& rgb,
                                            const FeatureParams& params);

struct ClusteringResult {
  std::vector<std::uint32_t> labels;  // per feature row, 0..k-1: its nearest centre
  CentreMatrix centres;               // k x 6
  int iterations = 0;
  bool converged = false;
  // The method's objective for the returned centres: the sum of squared distances to the
  // nearest centre (K-Means, SOM), J_m = sum u^m d^2 (FCM).
  double objective = 0;
  std::vector<double> objective_history;  // one value per iteration, in order
};

// Mean squared distance of the features to their labelled centres.
double quantisation_error(const ClusteringFeatures& features, const ClusteringResult& result);

// Labels of the feature rows at their pixels, geometry::kNoLabel (0xffffffff) everywhere else.
SegmentLabelImage label_image(const ClusteringFeatures& features, const ClusteringResult& result);

// Every valid pixel of the frame the features were made from (stride or not) labelled with its
// nearest centre under the same scaling; kNoLabel where the point is NaN.
SegmentLabelImage label_all_pixels(const PointImage& points, const RgbImage& rgb,
                                   const ClusteringFeatures& features,
                                   const ClusteringResult& result);

// Index of the nearest centre of each row (lowest index among equals) and its squared distance.
struct NearestCentres {
  std::vector<std::uint32_t> labels;
  std::vector<double> squared_distances;
};
NearestCentres nearest_centres(const FeatureMatrix& features, const CentreMatrix& centres);

namespace detail {

// The shared hot loop: features are cut into kChunks contiguous chunks (run on
// KARTOGRAF_CPU_THREADS threads, see src/compute/cpu_parallel.hpp) and each chunk into
// blocks of rows; visit(chunk, first_row, block, squared_distances) sees each block once, its
// rows as doubles and the block x k matrix of squared distances to the centres. Accumulating per
// chunk and combining in chunk order makes results independent of the thread count.
inline constexpr std::size_t kChunks = 8;
using DistanceBlockVisitor =
    std::function<void(std::size_t chunk, Eigen::Index first_row, const Eigen::MatrixXd& block,
                       const Eigen::MatrixXd& squared_distances)>;
void for_each_distance_block(const FeatureMatrix& features, const CentreMatrix& centres,
                             const DistanceBlockVisitor& visit);

// Throws Error unless 1 <= k <= features.size(); `method` names the caller in the message.
void check_cluster_count(const char* method, std::uint32_t k, const ClusteringFeatures& features);
void check_iterations(const char* method, int max_iterations, double tolerance);

// A uniform double in [0, 1) from 53 bits of a std::mt19937_64 draw, so seeded runs are the
// same with every standard library (std::uniform_real_distribution is not specified exactly).
template <class Engine>
double uniform01(Engine& engine) {
  return static_cast<double>(engine() >> 11) * 0x1.0p-53;
}

}  // namespace detail
}  // namespace kartograf::segmentation
