#pragma once
// Object detection on the grey normals image with a boosted cascade of Haar-like features
// (docs/methods.md M2 step 4; P. Viola, M. Jones, "Rapid Object Detection using a Boosted Cascade
// of Simple Features", CVPR 2001). Debian's OpenCV ships the detector but not opencv_traincascade,
// so Kartograf has its own: features on integral images, stages of gentle-AdaBoost decision stumps
// (cascade_training.hpp), a sliding-window multi-scale detector, clustering of overlapping
// windows, and a metric size check of each detection on the organized points under it.
//
// Window: square, HaarCascade::window pixels (20, as the paper). A window's feature values are
// divided by the window's grey standard deviation (floored at min_stddev), so that a changed grey
// mapping ("relighting") changes them little; every feature's weights sum to zero, so the window's
// mean cancels.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kartograf/core/color.hpp"
#include "kartograf/core/point_image.hpp"

namespace kartograf::semantic {

// Summed-area tables of an image and of its squares, (width + 1) x (height + 1), zero first
// row and column: the sum over any rectangle in four look-ups.
class IntegralImage {
 public:
  IntegralImage() = default;
  explicit IntegralImage(const GrayImage& image);

  int width() const { return width_; }  // of the image, not the tables
  int height() const { return height_; }
  // Sum of the pixels (x .. x + w - 1, y .. y + h - 1); the rectangle must lie inside the image.
  std::int64_t sum(int x, int y, int w, int h) const;
  std::int64_t squared_sum(int x, int y, int w, int h) const;

 private:
  std::int64_t at(const std::vector<std::int64_t>& table, int x, int y) const {
    return table[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_ + 1) +
                 static_cast<std::size_t>(x)];
  }
  int width_ = 0, height_ = 0;
  std::vector<std::int64_t> sums_, squares_;
};

// A rectangle of a Haar-like feature in window coordinates, with its weight.
struct HaarRect {
  int x = 0, y = 0, width = 0, height = 0;
  float weight = 0;
};

// Up to three weighted rectangles whose weights x areas sum to zero: two-rectangle edges
// (horizontal, vertical), three-rectangle lines (as a whole rectangle weighted -1 and its middle
// third +3), four-rectangle diagonals (whole -1, two diagonal quarters +2).
struct HaarFeature {
  std::array<HaarRect, 3> rects{};
  int rect_count = 0;
};

// Weighted rectangle sum of `feature` for the window whose top-left corner is (x, y).
double haar_value(const HaarFeature& feature, const IntegralImage& integral, int x, int y);

// Every feature of the five kinds in a window x window square whose rectangles start on
// multiples of position_step and whose unit cells are 1, 1 + size_step, ... pixels. Larger steps
// give fewer features (window 20: steps 1, 1: 78 460 features; 2, 1: 22 385; 2, 2: 6 180).
std::vector<HaarFeature> enumerate_haar_features(int window, int position_step, int size_step);

// A regression stump of gentle AdaBoost: left when the normalised feature value < threshold.
struct WeakStump {
  int feature = 0;  // index into HaarCascade::features
  float threshold = 0;
  float left = 0, right = 0;
};

// A window passes a stage when the sum of its stumps is >= threshold.
struct CascadeStage {
  std::vector<WeakStump> stumps;
  float threshold = 0;
};

struct HaarCascade {
  std::string object_class;  // e.g. "stairs"
  int window = 20;
  float min_stddev = 8;  // floor of the window's grey standard deviation in the normalisation
  std::vector<HaarFeature> features;  // only the ones the stumps use
  std::vector<CascadeStage> stages;
};

// The divisor of every feature value of the window at (x, y): its grey standard deviation,
// at least cascade.min_stddev.
double window_normaliser(const HaarCascade& cascade, const IntegralImage& integral, int x, int y);

// The number of stages the window at (x, y) passes (== stages.size() for a detection), and the
// last evaluated stage's margin (sum - threshold) in *margin when given.
int evaluate_window(const HaarCascade& cascade, const IntegralImage& integral, int x, int y,
                    double* margin = nullptr);

// A detection box in pixels of the detected image.
struct Detection {
  int x = 0, y = 0, width = 0, height = 0;
  double score = 0;   // the final stage's margin (after clustering: of the best member)
  int neighbors = 1;  // raw windows merged into it
};

double intersection_over_union(const Detection& a, const Detection& b);

struct DetectionParams {
  double scale_factor = 1.2;  // between pyramid levels, > 1
  int min_size = 20;          // smallest window side in image pixels (>= cascade window)
  int max_size = 0;           // largest; 0: the image's shorter side
  int step = 2;               // window stride in pyramid-level pixels
  double group_iou = 0.3;     // raw windows overlapping the best one this much join its cluster
  int min_neighbors = 3;      // clusters with fewer raw windows are dropped
};

// Raw windows that pass every stage, over a pyramid of the image (each level resized with area
// averaging), in image pixels. Throws Error on an empty cascade or bad parameters.
std::vector<Detection> detect_windows(const HaarCascade& cascade, const GrayImage& image,
                                      const DetectionParams& params = {});

// Greedy clustering (non-maximum suppression): the highest-scoring remaining window takes every
// remaining window with IoU >= group_iou; the cluster becomes the mean box of its members, with
// the best member's score and the member count. Clusters with < min_neighbors members go.
std::vector<Detection> non_maximum_suppression(std::vector<Detection> windows, double group_iou,
                                               int min_neighbors);

// detect_windows, then non_maximum_suppression.
std::vector<Detection> detect_objects(const HaarCascade& cascade, const GrayImage& image,
                                      const DetectionParams& params = {});

// Metric extent of a detection, from the organized points (sensor at the origin) under its box:
// range = median distance to the sensor over the valid points of the box's central half (the
// object, not what lies around it); width and height = range x the angle between the mean ray
// directions of the box's left and right (top and bottom) edge columns (rows). Frame-free: works
// for camera frames (z forward) and laser scans (z up) alike.
struct MetricSize {
  double width = 0, height = 0, range = 0;
  int valid_points = 0;  // in the central half
};

// nullopt when the box has too few valid points (fewer than min_valid_points in the central half
// or on an edge). Throws Error when the box is not inside the point image.
std::optional<MetricSize> measure_detection(const PointImage& points, const Detection& box,
                                            int min_valid_points = 10);

// Plausible metric size of a class, metres.
struct SizeLimits {
  double min_width = 0, max_width = 0, min_height = 0, max_height = 0;
  void validate(const std::string& what) const;  // throws Error naming `what`
};

// The detections whose measured size lies within limits (points: the image the grey normals
// image was computed from, same size).
std::vector<Detection> verify_metric_size(const std::vector<Detection>& detections,
                                          const PointImage& points, const SizeLimits& limits);

// Model files: OpenCV FileStorage (YAML; ".gz" compresses). Throws Error naming the path.
void save_cascade(const HaarCascade& cascade, const std::string& path);
HaarCascade load_cascade(const std::string& path);

}  // namespace kartograf::semantic
