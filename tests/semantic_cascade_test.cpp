// M2 object detection (kartograf::semantic, haar_cascade.hpp, cascade_training.hpp,
// synthetic_stairs.hpp): integral images and Haar features against brute force, a small cascade
// trained on an easy synthetic pattern that must find it, clustering, metric size checks, model
// files and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/semantic/cascade_training.hpp"
#include "kartograf/semantic/haar_cascade.hpp"
#include "kartograf/semantic/object_detector.hpp"
#include "kartograf/training/synthetic_stairs.hpp"

namespace kartograf::semantic {
namespace {

using training::render_stairs_view;
using training::stairs_positives;
using training::StairsView;
using training::StairsViewParams;

GrayImage random_image(int width, int height, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> level(0, 255);
  GrayImage image(width, height);
  for (std::uint8_t& p : image.pixels()) p = static_cast<std::uint8_t>(level(rng));
  return image;
}

std::int64_t brute_sum(const GrayImage& image, int x, int y, int w, int h, bool squared) {
  std::int64_t sum = 0;
  for (int r = y; r < y + h; ++r) {
    for (int c = x; c < x + w; ++c) sum += squared ? image(c, r) * image(c, r) : image(c, r);
  }
  return sum;
}

TEST(SemanticCascade, IntegralImageMatchesBruteForce) {
  const GrayImage image = random_image(23, 17, 1);
  const IntegralImage integral(image);
  EXPECT_EQ(integral.width(), 23);
  EXPECT_EQ(integral.height(), 17);
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 300; ++trial) {
    const int x = std::uniform_int_distribution<int>(0, 22)(rng);
    const int y = std::uniform_int_distribution<int>(0, 16)(rng);
    const int w = std::uniform_int_distribution<int>(1, 23 - x)(rng);
    const int h = std::uniform_int_distribution<int>(1, 17 - y)(rng);
    ASSERT_EQ(integral.sum(x, y, w, h), brute_sum(image, x, y, w, h, false));
    ASSERT_EQ(integral.squared_sum(x, y, w, h), brute_sum(image, x, y, w, h, true));
  }
}

TEST(SemanticCascade, HaarFeaturesMatchBruteForceAndIgnoreTheMean) {
  const int window = 8;
  const std::vector<HaarFeature> features = enumerate_haar_features(window, 1, 1);
  EXPECT_EQ(enumerate_haar_features(20, 1, 1).size(), 78460u);  // Viola-Jones' five kinds, 20x20
  const GrayImage image = random_image(12, 11, 3);
  const IntegralImage integral(image);
  GrayImage flat(12, 11, 77);
  const IntegralImage flat_integral(flat);
  for (const HaarFeature& f : features) {
    for (const auto& [x, y] : {std::pair{0, 0}, std::pair{3, 2}, std::pair{4, 3}}) {
      // Per pixel: the sum of the weights of the rectangles that cover it.
      double expected = 0;
      for (int r = 0; r < window; ++r) {
        for (int c = 0; c < window; ++c) {
          double weight = 0;
          for (int i = 0; i < f.rect_count; ++i) {
            const HaarRect& rect = f.rects[static_cast<std::size_t>(i)];
            if (c >= rect.x && c < rect.x + rect.width && r >= rect.y && r < rect.y + rect.height)
              weight += rect.weight;
          }
          expected += weight * image(x + c, y + r);
        }
      }
      ASSERT_DOUBLE_EQ(haar_value(f, integral, x, y), expected);
    }
    ASSERT_DOUBLE_EQ(haar_value(f, flat_integral, 2, 1), 0.0);  // weights sum to zero
  }
}

// The easy pattern: a bright plus sign on a dark square, with noise; backgrounds are smooth
// random blobs and stripes-free noise.
GrayImage plus_pattern(int side, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, 6.0);
  GrayImage image(side, side);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      const bool bar =
          std::abs(2 * x - side + 1) < side / 3 || std::abs(2 * y - side + 1) < side / 3;
      const double v = (bar ? 200 : 50) + noise(rng);
      image(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
    }
  }
  return image;
}

GrayImage smooth_background(int width, int height, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const double fx = 0.02 + 0.1 * u(rng), fy = 0.02 + 0.1 * u(rng), phase = 6 * u(rng);
  std::normal_distribution<double> noise(0.0, 6.0);
  GrayImage image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double v = 128 + 70 * std::sin(fx * x + phase) * std::cos(fy * y) + noise(rng);
      image(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
    }
  }
  return image;
}

struct TinyModel {
  HaarCascade cascade;
  CascadeTrainingReport report;
};

const TinyModel& tiny_model() {
  static const TinyModel model = [] {
    std::mt19937_64 rng(5);
    std::vector<GrayImage> positives;
    for (int i = 0; i < 60; ++i) positives.push_back(plus_pattern(20, rng));
    std::vector<TrainingBackground> backgrounds;
    for (int i = 0; i < 20; ++i) backgrounds.push_back({smooth_background(64, 48, rng), {}});
    CascadeTrainingParams params;
    params.object_class = "plus";
    params.feature_position_step = 2;
    params.feature_size_step = 2;
    params.max_stages = 4;
    params.max_stumps_per_stage = 10;
    params.negatives_per_stage = 300;
    params.max_windows_per_background = 30;
    TinyModel m;
    m.cascade = train_cascade(positives, backgrounds, params, &m.report);
    return m;
  }();
  return model;
}

TEST(SemanticCascade, TinyTrainingDetectsAnEasyPattern) {
  const TinyModel& model = tiny_model();
  ASSERT_FALSE(model.cascade.stages.empty());
  EXPECT_EQ(model.cascade.object_class, "plus");
  EXPECT_EQ(model.report.features_considered, 6180);  // window 20, steps 2, 2
  // The pattern at 40x40 pixels (pyramid level 2) at (50, 30) of a fresh background.
  std::mt19937_64 rng(99);
  GrayImage scene = smooth_background(120, 90, rng);
  const GrayImage object = plus_pattern(40, rng);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x) scene(50 + x, 30 + y) = object(x, y);
  }
  DetectionParams params;
  params.min_neighbors = 1;
  const std::vector<Detection> found = detect_objects(model.cascade, scene, params);
  const Detection truth{50, 30, 40, 40, 0, 1};
  ASSERT_FALSE(found.empty());
  double best_iou = 0;
  for (const Detection& d : found) best_iou = std::max(best_iou, intersection_over_union(d, truth));
  EXPECT_GE(best_iou, 0.5);
  // And the background without it yields (almost) nothing.
  std::mt19937_64 rng2(123);
  EXPECT_LE(detect_objects(model.cascade, smooth_background(120, 90, rng2), params).size(), 1u);
}

TEST(SemanticCascade, ModelFileRoundTripKeepsDetections) {
  const TinyModel& model = tiny_model();
  const std::string path =
      (std::filesystem::temp_directory_path() / "kartograf_cascade_test.yml.gz").string();
  save_cascade(model.cascade, path);
  const HaarCascade loaded = load_cascade(path);
  std::filesystem::remove(path);
  EXPECT_EQ(loaded.object_class, model.cascade.object_class);
  ASSERT_EQ(loaded.stages.size(), model.cascade.stages.size());
  ASSERT_EQ(loaded.features.size(), model.cascade.features.size());
  std::mt19937_64 rng(7);
  const GrayImage scene = smooth_background(80, 60, rng);
  const IntegralImage integral(scene);
  for (int y = 0; y + 20 <= 60; y += 3) {
    for (int x = 0; x + 20 <= 80; x += 3) {
      double a = 0, b = 0;
      ASSERT_EQ(evaluate_window(model.cascade, integral, x, y, &a),
                evaluate_window(loaded, integral, x, y, &b));
      ASSERT_FLOAT_EQ(static_cast<float>(a), static_cast<float>(b));
    }
  }
}

TEST(SemanticCascade, NonMaximumSuppressionClustersOverlappingWindows) {
  const std::vector<Detection> windows = {
      {10, 10, 20, 20, 1.0, 1},
      {12, 10, 20, 20, 3.0, 1},
      {10, 12, 20, 20, 2.0, 1},
      {100, 100, 20, 20, 5.0, 1},  // alone: dropped with min_neighbors 2
  };
  const std::vector<Detection> clusters = non_maximum_suppression(windows, 0.3, 2);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].neighbors, 3);
  EXPECT_DOUBLE_EQ(clusters[0].score, 3.0);  // the best member's
  EXPECT_EQ(clusters[0].x, 11);              // mean box: (10 + 12 + 10) / 3 rounded
  EXPECT_EQ(clusters[0].y, 11);
  EXPECT_EQ(clusters[0].width, 20);
  EXPECT_EQ(non_maximum_suppression(windows, 0.3, 1).size(), 2u);
  EXPECT_DOUBLE_EQ(intersection_over_union({0, 0, 10, 10, 0, 1}, {5, 0, 10, 10, 0, 1}),
                   50.0 / 150.0);
  EXPECT_DOUBLE_EQ(intersection_over_union({0, 0, 10, 10, 0, 1}, {20, 0, 10, 10, 0, 1}), 0.0);
}

// A wall facing a pinhole camera (focal 200 px) at 2 m: a 40-pixel box spans 0.4 m.
PointImage wall_points(double distance) {
  const double focal = 200, cx = 49.5, cy = 39.5;
  PointImage points(100, 80);
  for (int v = 0; v < 80; ++v) {
    for (int u = 0; u < 100; ++u) {
      points(u, v) = Point4f(static_cast<float>((u - cx) / focal * distance),
                             static_cast<float>((v - cy) / focal * distance),
                             static_cast<float>(distance), 1.0f);
    }
  }
  return points;
}

TEST(SemanticCascade, MetricSizeOfADetection) {
  const PointImage points = wall_points(2.0);
  const Detection box{30, 20, 40, 40, 0, 1};
  const auto size = measure_detection(points, box);
  ASSERT_TRUE(size.has_value());
  EXPECT_NEAR(size->width, 0.4, 0.01);
  EXPECT_NEAR(size->height, 0.4, 0.01);
  EXPECT_NEAR(size->range, 2.0, 0.02);
  // Verification keeps a plausible box and rejects the same pixels on a wall twice as far.
  const SizeLimits limits{0.3, 0.5, 0.3, 0.5};
  EXPECT_EQ(verify_metric_size({box}, points, limits).size(), 1u);
  EXPECT_TRUE(verify_metric_size({box}, wall_points(4.0), limits).empty());
  // No points under the box: no size, rejected.
  PointImage holes(100, 80, invalid_point());
  EXPECT_FALSE(measure_detection(holes, box).has_value());
  EXPECT_TRUE(verify_metric_size({box}, holes, limits).empty());
}

TEST(SemanticCascade, SyntheticStairsViewsAndPositives) {
  const compute::Context context = compute::Context::cpu();
  StairsViewParams options;
  options.width = 160, options.height = 120, options.focal = 125;
  const StairsView view = render_stairs_view(context, 3, true, options);
  ASSERT_TRUE(view.object.has_value());
  EXPECT_EQ(view.gray.width(), 160);
  const Detection& box = *view.object;
  EXPECT_EQ(box.width, box.height);
  EXPECT_GE(box.x, 0);
  EXPECT_LE(box.x + box.width, 160);
  EXPECT_LE(box.y + box.height, 120);
  // The square's metric size is what stairs_size_limits admits.
  EXPECT_EQ(verify_metric_size({box}, view.points, stairs_size_limits()).size(), 1u);
  std::mt19937_64 rng(1);
  const std::vector<GrayImage> positives = stairs_positives(view, 5, 20, rng);
  ASSERT_EQ(positives.size(), 5u);
  for (const GrayImage& p : positives) EXPECT_EQ(p.width(), 20);
  EXPECT_FALSE(render_stairs_view(context, 3, false, options).object.has_value());
}

// The shipped stairs cascade through ObjectDetector on held-out camera frames of 640x480 (twice
// the training views' size): it finds the stairs (IoU >= 0.5 with the true box) in at least 5 of 6
// views with stairs and nothing in 3 views without; the found stairs become a map object whose
// footprint lies around the stairs' points and whose cells the grid marks.
TEST(SemanticCascade, ShippedStairsDetectorPlacesStairsOnTheMap) {
  const compute::Context context = compute::Context::cpu();
  const ObjectDetector detector = ObjectDetector::stairs();
  EXPECT_EQ(detector.object_class(), "stairs");
  StairsViewParams options;
  options.width = 640, options.height = 480, options.focal = 500;
  int found = 0;
  for (std::uint64_t seed = 2000000; seed < 2000006; ++seed) {
    const StairsView view = render_stairs_view(context, seed, true, options);
    ASSERT_TRUE(view.object.has_value());
    const std::vector<ViewDetection> detections = detector.detect(context, view.points);
    const auto hit = std::find_if(detections.begin(), detections.end(), [&](const auto& d) {
      return intersection_over_union(d.box, *view.object) >= 0.5;
    });
    if (hit == detections.end()) continue;
    ++found;
    // Camera frame (y down) to a z-up map frame: (x, z, -y).
    std::vector<Eigen::Vector3d> up_points;
    for (const Eigen::Vector3d& p : hit->points) up_points.emplace_back(p.x(), p.z(), -p.y());
    const ObjectDetection object = to_map_detection(up_points, SemanticClass::furniture, "stairs");
    ASSERT_GE(object.footprint.size(), 3u);
    EXPECT_LT(object.z_max - object.z_min, 2.5);
    std::vector<Eigen::Vector3d> floor;
    std::vector<SemanticClass> labels;
    for (double x = -3; x <= 3; x += 0.05)
      for (double y = 0.5; y <= 7; y += 0.05) floor.emplace_back(x, y, object.z_min - 0.01);
    labels.assign(floor.size(), SemanticClass::floor);
    const SemanticGrid grid =
        build_semantic_grid(floor, labels, {}, std::vector<ObjectDetection>{object});
    const auto detection = std::find_if(grid.objects.begin(), grid.objects.end(),
                                        [](auto& o) { return o.kind == ObjectKind::detection; });
    ASSERT_NE(detection, grid.objects.end());
    EXPECT_EQ(detection->name, "stairs");
    EXPECT_GT(detection->cells.size(), 10u);
  }
  EXPECT_GE(found, 5);
  for (std::uint64_t seed = 2000100; seed < 2000103; ++seed) {
    EXPECT_TRUE(
        detector.detect(context, render_stairs_view(context, seed, false, options).points).empty());
  }
  EXPECT_THROW(to_map_detection(
                   {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2, 0, 1)},
                   SemanticClass::furniture, "a line"),
               Error);
}

TEST(SemanticCascade, BadInputThrows) {
  const GrayImage patch(20, 20, 0);
  const std::vector<TrainingBackground> backgrounds = {{GrayImage(40, 40, 0), {}}};
  CascadeTrainingParams params;
  EXPECT_THROW(train_cascade({}, backgrounds, params), Error);
  EXPECT_THROW(train_cascade({GrayImage(19, 20, 0)}, backgrounds, params), Error);
  EXPECT_THROW(train_cascade({patch}, {}, params), Error);
  EXPECT_THROW(train_cascade({patch}, {{GrayImage(10, 10, 0), {}}}, params), Error);
  params.min_hit_rate = 0;
  EXPECT_THROW(train_cascade({patch}, backgrounds, params), Error);

  EXPECT_THROW(detect_objects(HaarCascade{}, patch), Error);  // no stages
  DetectionParams bad;
  bad.min_size = 10;  // smaller than the window
  EXPECT_THROW(detect_objects(tiny_model().cascade, patch, bad), Error);
  EXPECT_THROW(enumerate_haar_features(1, 1, 1), Error);
  EXPECT_THROW(non_maximum_suppression({}, 0.0, 1), Error);

  EXPECT_THROW(measure_detection(wall_points(2.0), {90, 0, 20, 20, 0, 1}), Error);
  EXPECT_THROW(verify_metric_size({}, wall_points(2.0), SizeLimits{1, 0.5, 0, 1}), Error);
  EXPECT_THROW(load_cascade("/nonexistent/kartograf_cascade.yml.gz"), Error);
  EXPECT_THROW(render_stairs_view(compute::Context::cpu(), 1, true, StairsViewParams{.width = 5}),
               Error);
}

}  // namespace
}  // namespace kartograf::semantic
