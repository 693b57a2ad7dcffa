#pragma once
// Ground texture classes for outdoor traversability (docs/methods.md M2 step 5): a patch of
// coloured ground points is pavement (flat, uniform colour: preferred), grass (bumpy by a few cm,
// green, textured: traversable but avoided) or inaccessible (steep, steps, rubble, obstacles).
//
// Gravity is known: z is up. The features are height statistics after removing the patch's
// best-fit plane, the plane's slope, CIE-Lab colour statistics, colour uniformity and green-ness
// (GroundFeature lists them). A random forest (OpenCV cv::ml::RTrees, privately) classifies them.
//
// There is no outdoor data with ground truth, so the classifier is trained on synthetic patches
// (synthesize_ground_patch): tools/train_ground_texture writes the shipped model,
// models/semantic/ground_texture.yml.gz.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "kartograf/core/point_cloud.hpp"

namespace kartograf::semantic {

enum class GroundClass : std::uint8_t { pavement = 0, grass = 1, inaccessible = 2 };
inline constexpr int kGroundClassCount = 3;

std::string_view to_string(GroundClass ground);

// Traversability weight in [0, 1] per class (docs/methods.md M2 step 5: pavement 1.0, grass avoided
// 0.5, inaccessible 0.0).
double default_traversability(GroundClass ground);

// The feature vector, in this order (units in brackets).
enum class GroundFeature : int {
  height_std = 0,   // [m] std of heights above the best-fit plane (along its normal)
  height_range,     // [m] 98th minus 2nd percentile of those heights (robust to outliers)
  roughness,        // [m] RMS height difference between neighbouring cells of a grid over xy
  max_step,         // [m] largest height difference between neighbouring cells (steps, blocks)
  slope,            // [deg] angle between the plane's normal and z
  lab_l_mean,       // CIE-Lab L* mean
  lab_a_mean,       // a* mean (negative: green)
  lab_b_mean,       // b* mean
  lab_l_std,        // L* std
  lab_a_std,        // a* std
  lab_b_std,        // b* std
  color_entropy,    // [bits] entropy of an L*a*b* histogram (0: one colour)
  gradient_energy,  // mean squared L* difference between neighbouring grid cells
  greenness,        // mean excess green (2g - r - b) / (r + g + b), in [-1, 2]
  count
};
inline constexpr int kGroundFeatureCount = static_cast<int>(GroundFeature::count);
using GroundFeatures = std::array<float, kGroundFeatureCount>;

struct GroundFeatureParams {
  int min_points = 30;  // fewer points are no patch
  // Neighbour statistics (roughness, steps, gradient energy) use a grid over the patch's xy box
  // with about this many points a cell, at most max_grid_side cells a side.
  double points_per_cell = 3.0;
  int max_grid_side = 32;
};

// Features of one patch: `patch.points` (metres, z up) with `patch.colors` for every point.
// Throws Error when the patch has fewer than min_points points, no or a wrong number of colours,
// a non-finite point, or a degenerate extent (all points on a line or a spot).
GroundFeatures ground_features(const PointCloud& patch, const GroundFeatureParams& params = {});

// A random forest over GroundFeatures. Copies share the model.
class GroundTextureClassifier {
 public:
  struct TrainParams {
    int tree_count = 100;
    int max_depth = 12;
    int min_sample_count = 4;
  };

  GroundTextureClassifier() = default;
  bool empty() const { return !model_; }

  // Rows of kGroundFeatureCount features and a label per row. Throws Error when the sizes
  // disagree, a label is not a GroundClass, or a class has no row.
  static GroundTextureClassifier train(std::span<const float> features,
                                       std::span<const GroundClass> labels,
                                       const TrainParams& params);
  static GroundTextureClassifier train(std::span<const float> features,
                                       std::span<const GroundClass> labels) {
    return train(features, labels, TrainParams{});
  }
  // OpenCV FileStorage files (.yml, .yml.gz, .xml, ...). load throws Error naming the file when it
  // is missing, unreadable, not a trained classifier or trained on another feature count; save
  // when the model is empty or the file cannot be written.
  static GroundTextureClassifier load(const std::filesystem::path& path);
  void save(const std::filesystem::path& path) const;

  // Throws Error when the model is empty or features.size() is not a multiple of the row size.
  std::vector<GroundClass> predict(std::span<const float> features) const;
  GroundClass predict(const GroundFeatures& features) const;

 private:
  struct Model;
  explicit GroundTextureClassifier(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  std::shared_ptr<const Model> model_;
};

// The shipped model: $KARTOGRAF_GROUND_TEXTURE_MODEL when set, else
// <models folder>/semantic/ground_texture.yml.gz (core/models.hpp).
std::filesystem::path default_ground_texture_model_path();

// ---- Synthetic labelled patches ----------------------------------------------------------------

// Two generator families with different parameter ranges and partly different structure, so that
// a classifier trained on one is tested on patches it has not seen the like of:
//  - training: square slabs with straight joints, grass as random bumps plus blade noise, slopes
//    20-40 deg, steps, rubble of boxes;
//  - held_out: other patch sizes, densities, sensor noise and colours, rotated brick joints,
//    grass from smooth tussocks, slopes 22-50 deg, kerbs, rubble of spheres, posts.
enum class GroundPatchStyle : std::uint8_t { training, held_out };

// One patch of class `ground`, about 0.6-1.2 m across, z up; the same (class, style, seed) gives
// the same patch.
PointCloud synthesize_ground_patch(GroundClass ground, GroundPatchStyle style, std::uint64_t seed);

// `per_class` patches of each class with seeds derived from `seed`: their features (rows) and
// labels, class by class.
struct GroundSamples {
  std::vector<float> features;
  std::vector<GroundClass> labels;
};
GroundSamples synthesize_ground_samples(int per_class, GroundPatchStyle style, std::uint64_t seed,
                                        const GroundFeatureParams& params = {});

}  // namespace kartograf::semantic
