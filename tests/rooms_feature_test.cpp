// Feature-based room segmentation (rooms/laser_features.hpp, rooms/feature_segmentation.hpp):
// simulated scans and their features on hand-made maps with known answers, the classifier's
// training and file round trip, errors, and one real ipa map with the shipped model.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <random>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/rooms/feature_segmentation.hpp"
#include "kartograf/rooms/laser_features.hpp"
#include "room_test_maps.hpp"
#include "test_support.hpp"

namespace kartograf {
namespace {

using rooms::LaserFeatures;
using rooms::PlaceClass;

std::size_t feature_index(std::string_view name) {
  const auto& names = rooms::laser_feature_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return i;
  }
  ADD_FAILURE() << "no feature named " << name;
  return 0;
}

float feature(const LaserFeatures& f, std::string_view name) {
  return f[feature_index(name)];
}

std::filesystem::path shipped_model() {
  return rooms::default_room_classifier_path();
}

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("kartograf_rooms_feature_" + std::to_string(::getpid()) + "_" + name);
}

// A square room of 81 x 81 free cells with a one-cell wall, scanned from its centre cell (41, 41):
// a beam at angle t first samples a wall after ceil(40.5 / max(|cos t|, |sin t|)) steps.
TEST(LaserScanner, BeamsFromTheCentreOfASquareRoom) {
  const OccupancyGrid map = testing::carve_map(83, 83, {{1, 1, 82, 82}});
  const rooms::LaserScanner scanner(map);
  ASSERT_EQ(scanner.beams(), 360);
  std::vector<double> ranges(360);
  scanner.scan(41, 41, ranges);
  for (int k = 0; k < 360; ++k) {
    const double t = k * std::numbers::pi / 180;
    const double steps =
        std::ceil(40.5 / std::max(std::abs(std::cos(t)), std::abs(std::sin(t))) - 1e-9);
    EXPECT_NEAR(ranges[static_cast<std::size_t>(k)], steps * 0.05, 1e-9) << "beam " << k;
  }
  EXPECT_NEAR(ranges[0], 41 * 0.05, 1e-9);
  EXPECT_NEAR(ranges[45], 58 * 0.05, 1e-9);  // 40.5 * sqrt(2) = 57.3
}

TEST(LaserScanner, StopsAtMaxRangeAndGivesZerosOffFreeSpace) {
  const OccupancyGrid map = testing::carve_map(101, 101, {{1, 1, 100, 100}});
  const rooms::LaserScanner scanner(map, {72, 1.0});
  std::vector<double> ranges(72);
  scanner.scan(50, 50, ranges);
  for (const double r : ranges) EXPECT_NEAR(r, 1.0, 1e-9);
  scanner.scan(0, 0, ranges);  // a wall cell
  for (const double r : ranges) EXPECT_EQ(r, 0.0);
  std::vector<double> wrong(71);
  EXPECT_ERROR_MENTIONS(scanner.scan(50, 50, wrong), "72 beams", "71");
}

// Sphere tracing skips samples; it must stop at the same step as walking one cell at a time.
TEST(LaserScanner, SkippingMatchesStepByStepMarchingInClutter) {
  OccupancyGrid map = testing::carve_map(120, 90, {{1, 1, 119, 89}});
  std::mt19937 random(7);
  std::uniform_int_distribution<int> col(1, 118), row(1, 88);
  for (int i = 0; i < 300; ++i) map.cells(col(random), row(random)) = CellState::occupied;
  const rooms::LaserScanner scanner(map);
  std::vector<double> ranges(360);
  int scans = 0;
  for (int y = 3; y < 90; y += 11) {
    for (int x = 2; x < 120; x += 13) {
      if (map.cells(x, y) != CellState::free) continue;
      ++scans;
      scanner.scan(x, y, ranges);
      for (int k = 0; k < 360; ++k) {
        const double t = 2 * std::numbers::pi * k / 360;
        int step = 0;
        for (;; ++step) {
          // The scanner's beam directions are fixed point, 1/65536 cell (laser_features.hpp).
          const double px = x + 0.5 + step * (std::round(std::cos(t) * 65536) / 65536);
          const double py = y + 0.5 + step * (std::round(-std::sin(t) * 65536) / 65536);
          const int cx = static_cast<int>(std::floor(px)), cy = static_cast<int>(std::floor(py));
          if (cx < 0 || cy < 0 || cx >= map.width() || cy >= map.height() ||
              map.cells(cx, cy) != CellState::free)
            break;
        }
        ASSERT_NEAR(ranges[static_cast<std::size_t>(k)], step * 0.05, 1e-9)
            << "cell " << x << "," << y << " beam " << k;
      }
    }
  }
  EXPECT_GT(scans, 40);
}

// All beams 2 m: a regular 360-gon of circumradius 2.
TEST(LaserFeatures, CircularScan) {
  const std::vector<double> ranges(360, 2.0);
  const LaserFeatures f = rooms::laser_scan_features(ranges);
  const double step = 2 * std::numbers::pi / 360;
  EXPECT_NEAR(feature(f, "mean_beam"), 2.0, 1e-6);
  EXPECT_NEAR(feature(f, "std_beam"), 0.0, 1e-3);
  EXPECT_NEAR(feature(f, "mean_difference"), 0.0, 1e-6);
  EXPECT_EQ(feature(f, "gaps"), 0);
  EXPECT_EQ(feature(f, "relative_gaps"), 0);
  EXPECT_NEAR(feature(f, "mean_ratio"), 1.0, 1e-6);
  EXPECT_NEAR(feature(f, "polygon_area"), 180 * 4 * std::sin(step), 1e-4);
  EXPECT_NEAR(feature(f, "polygon_perimeter"), 360 * 4 * std::sin(step / 2), 1e-4);
  EXPECT_NEAR(feature(f, "major_semi_axis"), 2.0, 1e-3);  // a disc's variance is r^2 / 4
  EXPECT_NEAR(feature(f, "minor_semi_axis"), 2.0, 1e-3);
  EXPECT_NEAR(feature(f, "axis_ratio"), 1.0, 1e-4);
  EXPECT_NEAR(feature(f, "compactness"), 1.0, 1e-3);
  EXPECT_NEAR(feature(f, "centroid_offset"), 0.0, 1e-5);
  EXPECT_NEAR(feature(f, "mean_centroid_distance"), 2.0, 1e-5);
  EXPECT_NEAR(feature(f, "minima_angle"), 90.0,
              1e-4);  // ties: the first beam and a quarter turn on
  EXPECT_NEAR(feature(f, "minima_distance"), 2 * std::sqrt(2.0), 1e-5);
  EXPECT_NEAR(feature(f, "shortest_beam"), 2.0, 1e-6);
  EXPECT_NEAR(feature(f, "mean_beam_per_max"), 1.0, 1e-6);
}

// Beams 90..269 3 m, the others 1 m: two half-discs, two jumps between consecutive beams.
TEST(LaserFeatures, TwoHalfDiscs) {
  std::vector<double> ranges(360, 1.0);
  for (int k = 90; k < 270; ++k) ranges[static_cast<std::size_t>(k)] = 3.0;
  const LaserFeatures f = rooms::laser_scan_features(ranges);
  EXPECT_NEAR(feature(f, "mean_beam"), 2.0, 1e-6);
  EXPECT_NEAR(feature(f, "std_beam"), 1.0, 1e-6);
  EXPECT_EQ(feature(f, "gaps"), 2);           // |3 - 1| > 0.5 at 89/90 and 269/270
  EXPECT_EQ(feature(f, "relative_gaps"), 2);  // 1/3 < 0.5
  EXPECT_NEAR(feature(f, "mean_difference"), 2.0 * 2 / 360, 1e-6);
  EXPECT_NEAR(feature(f, "beam_kurtosis"), -2.0, 1e-5);  // two equal spikes: m4 / m2^2 = 1
  // 179 triangles of each radius and the two between them, each with a 1-degree apex.
  const double sin1 = std::sin(std::numbers::pi / 180);
  EXPECT_NEAR(feature(f, "polygon_area"), 0.5 * sin1 * (179 * 1 + 179 * 9 + 2 * 3), 1e-4);
  EXPECT_NEAR(feature(f, "longest_beam"), 3.0, 1e-6);
  // Beam 0 and beam 270, the first 1 m beam a quarter turn away.
  EXPECT_NEAR(feature(f, "minima_angle"), 90.0, 1e-4);
  EXPECT_NEAR(feature(f, "minima_distance"), std::sqrt(2.0), 1e-5);
}

TEST(LaserFeatures, RejectBadScans) {
  EXPECT_ERROR_MENTIONS(rooms::laser_scan_features(std::vector<double>(4, 1.0)),
                        "at least 8 beams");
  std::vector<double> ranges(36, 1.0);
  ranges[3] = 0.0;
  EXPECT_ERROR_MENTIONS(rooms::laser_scan_features(ranges), "> 0");
  EXPECT_ERROR_MENTIONS(rooms::LaserScanner(testing::carve_map(10, 10, {{1, 1, 9, 9}}), {4, 10.0}),
                        "beams must be >= 8");
}

// Rows of features whose class follows one feature: the classifier must learn it, and read back
// from a gzipped file it must score exactly as before.
TEST(RoomClassifier, TrainSaveLoadRoundTrip) {
  std::mt19937 random(3);
  std::uniform_real_distribution<float> value(0.f, 4.f);
  std::vector<float> features;
  std::vector<int> labels;
  for (int i = 0; i < 400; ++i) {
    LaserFeatures f;
    for (float& v : f) v = value(random);
    features.insert(features.end(), f.begin(), f.end());
    labels.push_back(f[feature_index("mean_beam")] > 2.f ? 1 : -1);
  }
  const rooms::RoomClassifier trained = rooms::RoomClassifier::train(features, labels, 20, 2);
  const std::vector<float> scores = trained.scores(features);
  int right = 0;
  for (std::size_t i = 0; i < labels.size(); ++i) right += (scores[i] > 0) == (labels[i] > 0);
  EXPECT_GE(right, 396);
  const std::filesystem::path path = temp_path("model.yml.gz");
  trained.save(path);
  const rooms::RoomClassifier loaded = rooms::RoomClassifier::load(path);
  EXPECT_EQ(loaded.scores(features), scores);
  std::filesystem::remove(path);
}

TEST(RoomClassifier, ClearErrors) {
  const std::filesystem::path missing = temp_path("missing.yml.gz");
  EXPECT_ERROR_MENTIONS(rooms::RoomClassifier::load(missing), missing.string(), "does not exist");
  const std::filesystem::path corrupt = temp_path("corrupt.yml");
  testing::write_file(corrupt, std::string_view("%YAML:1.0\nnot: [a, boosted, classifier\n"));
  EXPECT_ERROR_MENTIONS(rooms::RoomClassifier::load(corrupt), corrupt.string());
  const std::filesystem::path other = temp_path("other.yml");
  testing::write_file(other, std::string_view("%YAML:1.0\n---\nanswer: 42\n"));
  EXPECT_ERROR_MENTIONS(rooms::RoomClassifier::load(other), other.string());
  std::filesystem::remove(corrupt);
  std::filesystem::remove(other);

  EXPECT_ERROR_MENTIONS(
      rooms::RoomClassifier::train(std::vector<float>(27, 1.f), std::vector<int>{1}),
      "room and hallway samples");
  EXPECT_ERROR_MENTIONS(
      rooms::RoomClassifier::train(std::vector<float>(26, 1.f), std::vector<int>{1}),
      "26 features for 1 labels");
  const rooms::RoomClassifier empty;
  EXPECT_ERROR_MENTIONS(
      rooms::segment_feature_based(compute::Context::cpu(), testing::rooms_in_a_row(2), empty),
      "classifier is empty");
  EXPECT_ERROR_MENTIONS(empty.save(temp_path("empty.yml")), "empty model");
}

// Trained on a hand-made floor (4 rooms off a corridor), the method must find those rooms again.
TEST(FeatureSegmentation, LearnsAndSegmentsRoomsOffACorridor) {
  LabelImage truth;
  const OccupancyGrid map = testing::rooms_off_a_corridor(4, &truth);
  Label corridor = 0;
  for (const Label l : truth.pixels()) corridor = std::max(corridor, l);
  rooms::RoomTrainingMap training{"rooms off a corridor", map,
                                  Image<PlaceClass>(map.width(), map.height(), PlaceClass::none)};
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Label l = truth.data()[i];
    if (l != 0) training.places.data()[i] = l == corridor ? PlaceClass::hallway : PlaceClass::room;
  }
  rooms::ClassifierTrainingParams params;
  params.weak_count = 40;
  params.sample_stride = 2;
  const rooms::RoomClassifier classifier =
      rooms::train_room_classifier(compute::Context::cpu(), {training}, params);

  const Image<PlaceClass> places = rooms::classify_places(compute::Context::cpu(), map, classifier);
  int labelled = 0, right = 0;
  for (std::size_t i = 0; i < places.size(); ++i) {
    if (training.places.data()[i] == PlaceClass::none) continue;
    ++labelled;
    right += places.data()[i] == training.places.data()[i];
  }
  EXPECT_GT(right, 0.97 * labelled) << right << " of " << labelled;

  const rooms::RoomSegmentation result =
      rooms::segment_feature_based(compute::Context::cpu(), map, classifier);
  EXPECT_EQ(result.method, "feature");
  EXPECT_EQ(result.records.size(), 5u);
  const auto scores = eval::evaluate_room_segmentation(truth, result.rooms);
  EXPECT_GT(scores.recall_mean, 0.95);
  EXPECT_GT(scores.precision_mean, 0.95);
}

TEST(FeatureSegmentation, TrainingMapsFromDrawings) {
  // Drawn free space 6 cells, 2 of them white: in a room drawing those are hallway, the rest room.
  const OccupancyGrid drawn = testing::carve_map(4, 3, {{0, 0, 3, 2}});
  const OccupancyGrid white = testing::carve_map(4, 3, {{0, 0, 2, 1}});
  const rooms::RoomTrainingMap t =
      rooms::room_training_map("drawing", drawn, white, PlaceClass::hallway);
  EXPECT_EQ(t.places(0, 0), PlaceClass::hallway);
  EXPECT_EQ(t.places(1, 0), PlaceClass::hallway);
  EXPECT_EQ(t.places(2, 0), PlaceClass::room);
  EXPECT_EQ(t.places(2, 1), PlaceClass::room);
  EXPECT_EQ(t.places(3, 0), PlaceClass::none);
  EXPECT_ERROR_MENTIONS(rooms::room_training_map("drawing", white, drawn, PlaceClass::room),
                        "drawing", "white cell outside");
  EXPECT_ERROR_MENTIONS(rooms::train_room_classifier(compute::Context::cpu(), {}),
                        "no training maps");
}

TEST(FeatureSegmentation, RejectsBadInput) {
  const rooms::RoomClassifier classifier = rooms::RoomClassifier::load(shipped_model());
  EXPECT_ERROR_MENTIONS(rooms::segment_feature_based(compute::Context::cpu(),
                                                     testing::carve_map(5, 5, {}), classifier),
                        "feature-based room segmentation");
  rooms::FeatureSegmentationParams params;
  params.region_area = {2.0, 1.0};
  EXPECT_ERROR_MENTIONS(
      rooms::segment_feature_based(compute::Context::cpu(), testing::rooms_in_a_row(2), classifier,
                                   params),
      "area limits");
  params = {};
  params.sample_stride = 0;
  EXPECT_ERROR_MENTIONS(
      rooms::segment_feature_based(compute::Context::cpu(), testing::rooms_in_a_row(2), classifier,
                                   params),
      "sample_stride");
}

// One real map with the shipped model (trained on the ipa training drawings), against its ground
// truth (office_c, plain).
TEST(FeatureSegmentation, RealIpaMap) {
  const rooms::RoomClassifier classifier = rooms::RoomClassifier::load(shipped_model());
  const auto scores = testing::benchmark_map_scores("office_c", [&](const OccupancyGrid& map) {
    return rooms::segment_feature_based(compute::Context::cpu(), map, classifier);
  });
  EXPECT_GT(scores.recall_mean, 0.96);     // measured 0.990
  EXPECT_GT(scores.precision_mean, 0.95);  // measured 0.976
}

}  // namespace
}  // namespace kartograf
