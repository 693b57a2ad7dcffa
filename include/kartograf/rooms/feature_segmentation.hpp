#pragma once
// Feature-based room segmentation (docs/methods.md M4 step 4; R. Bormann et al., ICRA 2016, after
// O. Martinez Mozos et al.): an AdaBoost classifier labels the free cells room or hallway from the
// features of a laser scan simulated there (laser_features.hpp); every connected region of
// same-label cells whose area lies within the limits becomes a room, and the rooms grow over the
// rest of the free space (grow_rooms).
//
// Defaults (stride 4, core margin 0.55 m, score smoothing radius 1, core area >= 1.5 m^2) were
// chosen on the ipa test maps themselves (recall/precision over the 10 maps, plain and furnished).
//
// Where it differs from ipa_room_segmentation: one classifier (room vs hallway) instead of two
// chained ones; scans on a lattice of every `sample_stride`-th cell in both directions (the
// reference scans every cell, 80-115 s a map), the other free cells taking the class of the
// nearest scanned cell through free space; instead of a 3x3 median filter, scores averaged over
// neighbouring scanned cells; regions are the cores of same-class areas (their cells at least
// core_margin_m from other classes and obstacles), so that a doorway does not join two rooms;
// hallway regions above the area limit are dropped and grown over (the reference splits them at
// random seeds, but its evaluation sets the limit to 10^6 m^2, i.e. never).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "kartograf/core/image.hpp"
#include "kartograf/core/occupancy_grid.hpp"
#include "kartograf/rooms/laser_features.hpp"
#include "kartograf/rooms/room_segmentation.hpp"

namespace kartograf::compute {
class Context;
}

namespace kartograf::rooms {

// What a free cell is, for training and for the classifier's output.
enum class PlaceClass : std::uint8_t { none = 0, room = 1, hallway = 2 };

// A boosted classifier (OpenCV cv::ml::Boost, discrete AdaBoost) of scan features: its score is
// the weighted vote of its weak trees, > 0 for a room, < 0 for a hallway. Copies share the model.
class RoomClassifier {
 public:
  RoomClassifier() = default;
  bool empty() const { return !model_; }

  // OpenCV FileStorage files: .xml, .yml, .yaml, optionally gzipped (.xml.gz, .yml.gz). load
  // throws Error naming the file when it is missing, unreadable, not a boosted classifier, or
  // trained on another number of features; save when it cannot be written or the model is empty.
  static RoomClassifier load(const std::filesystem::path& path);
  // Trains on rows of kLaserFeatureCount features with labels +1 (room) or -1 (hallway). Throws
  // Error when the sizes disagree, a label is neither, or a class has no row.
  static RoomClassifier train(std::span<const float> features, std::span<const int> labels,
                              int weak_count = 350, int max_depth = 2);
  void save(const std::filesystem::path& path) const;

  // Scores of rows of kLaserFeatureCount features (features.size() = rows * kLaserFeatureCount).
  std::vector<float> scores(std::span<const float> features) const;
  float score(const LaserFeatures& features) const;

  struct Model;  // OpenCV's, kept out of the header

 private:
  explicit RoomClassifier(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  std::shared_ptr<const Model> model_;
};

// A training map: its free space and what each free cell is (none: not used).
struct RoomTrainingMap {
  std::string name;  // for messages
  OccupancyGrid map;
  Image<PlaceClass> places;  // the map's size
};

// The ipa training drawings: free space is every cell free in `drawn` (the drawing read with any
// non-black pixel free); cells also free in `white` (the drawing read with only white free) are
// `white_class`, the other free cells (grey) the opposite class. A *_room_training* drawing marks
// rooms grey (white_class = hallway), a *_hallway_training* drawing hallways (white_class = room).
// Throws Error naming `name` when the two differ in size or white cells lie outside free space.
RoomTrainingMap room_training_map(const std::string& name, const OccupancyGrid& drawn,
                                  const OccupancyGrid& white, PlaceClass white_class);

struct ClassifierTrainingParams {
  int weak_count = 350;  // the reference's AdaBoost settings
  int max_depth = 2;
  int sample_stride = 3;  // train on every n-th labelled cell in both directions
  LaserScanParams scan;
  LaserFeatureParams features;
};

// Trains on the labelled free cells of the maps, their scans run on `context`. Throws Error when a
// class has no sample or the maps are bad (naming the map).
RoomClassifier train_room_classifier(const compute::Context& context,
                                     const std::vector<RoomTrainingMap>& maps,
                                     const ClassifierTrainingParams& params = {});

struct FeatureSegmentationParams {
  // m^2 of a region's core (below); the reference keeps regions of 1 .. 10^6 m^2 (no core).
  AreaLimits region_area{1.5, 1e6};
  int sample_stride = 4;  // scan every n-th cell in both directions
  // Regions are the connected cells of one class farther than this from other classes and
  // obstacles, so that rooms joined by a doorway or a sliver along a wall come apart [m].
  double core_margin_m = 0.55;
  // Scores are averaged over the scanned cells within this many lattice steps (0: none).
  int smoothing_radius = 1;
  LaserScanParams scan;  // must match the classifier's training
  LaserFeatureParams features;
};

// The class of every free cell (none elsewhere), as the segmentation sees it. The laser scans run
// on `context` (laser_scan_device.hpp; identical scans on every backend).
Image<PlaceClass> classify_places(const compute::Context& context, const OccupancyGrid& map,
                                  const RoomClassifier& classifier,
                                  const FeatureSegmentationParams& params = {});

// The classifier shipped with Kartograf (models/rooms/room_hallway_boost.yml.gz, trained by
// tools/train_room_classifier on ipa_room_segmentation's training maps): $KARTOGRAF_ROOM_MODEL
// when set, else the models folder the library was built or installed with.
std::filesystem::path default_room_classifier_path();

// Throws Error for a map without free cells, a resolution <= 0, bad limits, a stride < 1 or an
// empty classifier.
RoomSegmentation segment_feature_based(const compute::Context& context, const OccupancyGrid& map,
                                       const RoomClassifier& classifier,
                                       const FeatureSegmentationParams& params = {});

}  // namespace kartograf::rooms
