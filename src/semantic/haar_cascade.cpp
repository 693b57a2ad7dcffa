#include "kartograf/semantic/haar_cascade.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"
#include "semantic/haar_pyramid.hpp"

namespace kartograf::semantic {

IntegralImage::IntegralImage(const GrayImage& image)
    : width_(image.width()), height_(image.height()) {
  const std::size_t stride = static_cast<std::size_t>(width_ + 1);
  sums_.assign(stride * static_cast<std::size_t>(height_ + 1), 0);
  squares_.assign(sums_.size(), 0);
  for (int y = 0; y < height_; ++y) {
    std::int64_t row_sum = 0, row_squares = 0;
    for (int x = 0; x < width_; ++x) {
      const std::int64_t v = image(x, y);
      row_sum += v;
      row_squares += v * v;
      const std::size_t i =
          static_cast<std::size_t>(y + 1) * stride + static_cast<std::size_t>(x + 1);
      sums_[i] = sums_[i - stride] + row_sum;
      squares_[i] = squares_[i - stride] + row_squares;
    }
  }
}

std::int64_t IntegralImage::sum(int x, int y, int w, int h) const {
  return at(sums_, x + w, y + h) - at(sums_, x, y + h) - at(sums_, x + w, y) + at(sums_, x, y);
}

std::int64_t IntegralImage::squared_sum(int x, int y, int w, int h) const {
  return at(squares_, x + w, y + h) - at(squares_, x, y + h) - at(squares_, x + w, y) +
         at(squares_, x, y);
}

double haar_value(const HaarFeature& feature, const IntegralImage& integral, int x, int y) {
  double value = 0;
  for (int i = 0; i < feature.rect_count; ++i) {
    const HaarRect& r = feature.rects[static_cast<std::size_t>(i)];
    value += r.weight * static_cast<double>(integral.sum(x + r.x, y + r.y, r.width, r.height));
  }
  return value;
}

std::vector<HaarFeature> enumerate_haar_features(int window, int position_step, int size_step) {
  require(window >= 2 && position_step >= 1 && size_step >= 1,
          "enumerate_haar_features: window must be >= 2 and steps >= 1, got window " +
              std::to_string(window) + ", steps " + std::to_string(position_step) + ", " +
              std::to_string(size_step));
  // Each kind: its grid of unit cells (columns x rows) and the weighted sub-rectangles in cells.
  struct Kind {
    int columns, rows;
    std::vector<std::array<int, 5>> cells;  // x, y, w, h (in cells), weight
  };
  const std::vector<Kind> kinds = {
      {2, 1, {{0, 0, 1, 1, 1}, {1, 0, 1, 1, -1}}},                   // edge, left | right
      {1, 2, {{0, 0, 1, 1, 1}, {0, 1, 1, 1, -1}}},                   // edge, top / bottom
      {3, 1, {{0, 0, 3, 1, -1}, {1, 0, 1, 1, 3}}},                   // line, vertical bar
      {1, 3, {{0, 0, 1, 3, -1}, {0, 1, 1, 1, 3}}},                   // line, horizontal bar
      {2, 2, {{0, 0, 2, 2, -1}, {0, 0, 1, 1, 2}, {1, 1, 1, 1, 2}}},  // diagonal
  };
  std::vector<HaarFeature> features;
  for (const Kind& kind : kinds) {
    for (int cw = 1; cw * kind.columns <= window; cw += size_step) {
      for (int ch = 1; ch * kind.rows <= window; ch += size_step) {
        for (int y = 0; y + ch * kind.rows <= window; y += position_step) {
          for (int x = 0; x + cw * kind.columns <= window; x += position_step) {
            HaarFeature f;
            for (const auto& c : kind.cells) {
              f.rects[static_cast<std::size_t>(f.rect_count++)] = {
                  x + c[0] * cw, y + c[1] * ch, c[2] * cw, c[3] * ch, static_cast<float>(c[4])};
            }
            features.push_back(f);
          }
        }
      }
    }
  }
  return features;
}

double window_normaliser(const HaarCascade& cascade, const IntegralImage& integral, int x, int y) {
  const int w = cascade.window;
  const double area = static_cast<double>(w) * w;
  const double mean = static_cast<double>(integral.sum(x, y, w, w)) / area;
  const double variance =
      static_cast<double>(integral.squared_sum(x, y, w, w)) / area - mean * mean;
  return std::max(std::sqrt(std::max(variance, 0.0)), static_cast<double>(cascade.min_stddev));
}

int evaluate_window(const HaarCascade& cascade, const IntegralImage& integral, int x, int y,
                    double* margin) {
  const double inverse_norm = 1.0 / window_normaliser(cascade, integral, x, y);
  int passed = 0;
  for (const CascadeStage& stage : cascade.stages) {
    double sum = 0;
    for (const WeakStump& s : stage.stumps) {
      const double v =
          haar_value(cascade.features[static_cast<std::size_t>(s.feature)], integral, x, y) *
          inverse_norm;
      sum += v < s.threshold ? s.left : s.right;
    }
    if (margin) *margin = sum - stage.threshold;
    if (sum < stage.threshold) return passed;
    ++passed;
  }
  return passed;
}

double intersection_over_union(const Detection& a, const Detection& b) {
  const int ix = std::max(0, std::min(a.x + a.width, b.x + b.width) - std::max(a.x, b.x));
  const int iy = std::max(0, std::min(a.y + a.height, b.y + b.height) - std::max(a.y, b.y));
  const double inter = static_cast<double>(ix) * iy;
  const double uni =
      static_cast<double>(a.width) * a.height + static_cast<double>(b.width) * b.height - inter;
  return uni > 0 ? inter / uni : 0.0;
}

namespace {

void check_cascade(const HaarCascade& cascade, const std::string& what) {
  require(cascade.window >= 2,
          what + ": cascade window must be >= 2, got " + std::to_string(cascade.window));
  require(!cascade.stages.empty(), what + ": the cascade has no stages");
  for (const CascadeStage& stage : cascade.stages) {
    for (const WeakStump& s : stage.stumps) {
      require(s.feature >= 0 && static_cast<std::size_t>(s.feature) < cascade.features.size(),
              what + ": a stump names feature " + std::to_string(s.feature) + " of " +
                  std::to_string(cascade.features.size()));
    }
  }
}

cv::Mat to_mat(const GrayImage& image) {
  return cv::Mat(image.height(), image.width(), CV_8UC1, const_cast<std::uint8_t*>(image.data()));
}

GrayImage from_mat(const cv::Mat& mat) {
  GrayImage image(mat.cols, mat.rows);
  for (int y = 0; y < mat.rows; ++y) {
    std::copy_n(mat.ptr<std::uint8_t>(y), mat.cols,
                image.data() + static_cast<std::size_t>(y) * mat.cols);
  }
  return image;
}

}  // namespace

std::vector<PyramidLevel> build_pyramid(const GrayImage& image, int window,
                                        const DetectionParams& params) {
  require(params.scale_factor > 1.0 && params.step >= 1 && params.min_size >= window &&
              (params.max_size == 0 || params.max_size >= params.min_size),
          "Haar detection: need scale_factor > 1, step >= 1, cascade window (" +
              std::to_string(window) + ") <= min_size (" + std::to_string(params.min_size) +
              ") <= max_size (or max_size 0)");
  std::vector<PyramidLevel> levels;
  if (image.empty()) return levels;
  const int max_size =
      params.max_size > 0 ? params.max_size : std::min(image.width(), image.height());
  const cv::Mat source = to_mat(image);
  for (double side = params.min_size; side <= max_size; side *= params.scale_factor) {
    const double scale = side / window;
    const int lw = static_cast<int>(std::lround(image.width() / scale));
    const int lh = static_cast<int>(std::lround(image.height() / scale));
    if (lw < window || lh < window) break;
    cv::Mat level;
    cv::resize(source, level, cv::Size(lw, lh), 0, 0, cv::INTER_AREA);
    PyramidLevel out;
    out.scale = scale;
    out.image = from_mat(level);
    out.integral = IntegralImage(out.image);
    levels.push_back(std::move(out));
  }
  return levels;
}

GrayImage crop(const GrayImage& image, int x, int y, int side) {
  require(x >= 0 && y >= 0 && side > 0 && x + side <= image.width() && y + side <= image.height(),
          "crop: square outside the image");
  GrayImage out(side, side);
  for (int r = 0; r < side; ++r) {
    for (int c = 0; c < side; ++c) out(c, r) = image(x + c, y + r);
  }
  return out;
}

std::vector<Detection> detect_windows(const HaarCascade& cascade, const GrayImage& image,
                                      const DetectionParams& params) {
  check_cascade(cascade, "detect_windows");
  const int w = cascade.window;
  std::vector<Detection> windows;
  for (const PyramidLevel& level : build_pyramid(image, w, params)) {
    const int side = std::min(static_cast<int>(std::lround(w * level.scale)),
                              std::min(image.width(), image.height()));
    for (int y = 0; y + w <= level.integral.height(); y += params.step) {
      for (int x = 0; x + w <= level.integral.width(); x += params.step) {
        double margin = 0;
        if (evaluate_window(cascade, level.integral, x, y, &margin) ==
            static_cast<int>(cascade.stages.size())) {
          // Rounding may push the last windows a pixel past the border: keep boxes inside.
          windows.push_back(
              {std::min(static_cast<int>(std::lround(x * level.scale)), image.width() - side),
               std::min(static_cast<int>(std::lround(y * level.scale)), image.height() - side),
               side, side, margin, 1});
        }
      }
    }
  }
  return windows;
}

std::vector<Detection> non_maximum_suppression(std::vector<Detection> windows, double group_iou,
                                               int min_neighbors) {
  require(group_iou > 0 && group_iou <= 1 && min_neighbors >= 1,
          "non_maximum_suppression: need 0 < group_iou <= 1 and min_neighbors >= 1");
  std::sort(windows.begin(), windows.end(),
            [](const Detection& a, const Detection& b) { return a.score > b.score; });
  std::vector<bool> taken(windows.size(), false);
  std::vector<Detection> clusters;
  for (std::size_t i = 0; i < windows.size(); ++i) {
    if (taken[i]) continue;
    double x = 0, y = 0, w = 0, h = 0;
    int boxes = 0, members = 0;
    for (std::size_t j = i; j < windows.size(); ++j) {
      if (taken[j] || intersection_over_union(windows[i], windows[j]) < group_iou) continue;
      taken[j] = true;
      const Detection& m = windows[j];
      x += m.x, y += m.y, w += m.width, h += m.height;
      ++boxes;
      members += std::max(1, m.neighbors);  // a window may itself be a cluster
    }
    if (members < min_neighbors) continue;
    clusters.push_back({static_cast<int>(std::lround(x / boxes)),
                        static_cast<int>(std::lround(y / boxes)),
                        static_cast<int>(std::lround(w / boxes)),
                        static_cast<int>(std::lround(h / boxes)), windows[i].score, members});
  }
  return clusters;
}

std::vector<Detection> detect_objects(const HaarCascade& cascade, const GrayImage& image,
                                      const DetectionParams& params) {
  return non_maximum_suppression(detect_windows(cascade, image, params), params.group_iou,
                                 params.min_neighbors);
}

namespace {

// Mean unit ray direction (from the sensor at the origin) of the valid points in a rectangle.
std::optional<Eigen::Vector3d> mean_ray(const PointImage& points, int x0, int y0, int w, int h,
                                        int min_valid_points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      const Point4f& p = points(x, y);
      if (!is_valid(p)) continue;
      const Eigen::Vector3d d = p.head<3>().cast<double>();
      if (d.norm() <= 0) continue;
      sum += d.normalized();
      ++count;
    }
  }
  if (count < std::max(1, min_valid_points / 4)) return std::nullopt;
  return sum.normalized();
}

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

std::optional<MetricSize> measure_detection(const PointImage& points, const Detection& box,
                                            int min_valid_points) {
  require(box.width > 0 && box.height > 0 && box.x >= 0 && box.y >= 0 &&
              box.x + box.width <= points.width() && box.y + box.height <= points.height(),
          "measure_detection: box (" + std::to_string(box.x) + ", " + std::to_string(box.y) + ", " +
              std::to_string(box.width) + "x" + std::to_string(box.height) +
              ") is not inside the " + std::to_string(points.width()) + "x" +
              std::to_string(points.height()) + " point image");
  // Range: median over the central half of the box.
  std::vector<double> ranges;
  const int cx0 = box.x + box.width / 4, cy0 = box.y + box.height / 4;
  for (int y = cy0; y < cy0 + std::max(1, box.height / 2); ++y) {
    for (int x = cx0; x < cx0 + std::max(1, box.width / 2); ++x) {
      const Point4f& p = points(x, y);
      if (is_valid(p)) ranges.push_back(p.head<3>().cast<double>().norm());
    }
  }
  if (static_cast<int>(ranges.size()) < min_valid_points) return std::nullopt;
  std::nth_element(ranges.begin(), ranges.begin() + static_cast<std::ptrdiff_t>(ranges.size() / 2),
                   ranges.end());
  MetricSize size;
  size.range = ranges[ranges.size() / 2];
  size.valid_points = static_cast<int>(ranges.size());
  // Edge bands one tenth of the box wide (at least one pixel) average out single dropouts.
  const int band_x = std::max(1, box.width / 10), band_y = std::max(1, box.height / 10);
  const auto left = mean_ray(points, box.x, box.y, band_x, box.height, min_valid_points);
  const auto right =
      mean_ray(points, box.x + box.width - band_x, box.y, band_x, box.height, min_valid_points);
  const auto top = mean_ray(points, box.x, box.y, box.width, band_y, min_valid_points);
  const auto bottom =
      mean_ray(points, box.x, box.y + box.height - band_y, box.width, band_y, min_valid_points);
  if (!left || !right || !top || !bottom) return std::nullopt;
  // The bands' centres lie (box - band) apart; scale the angle to the full box.
  const double fx = static_cast<double>(box.width) / std::max(1, box.width - band_x);
  const double fy = static_cast<double>(box.height) / std::max(1, box.height - band_y);
  size.width = size.range * angle_between(*left, *right) * fx;
  size.height = size.range * angle_between(*top, *bottom) * fy;
  return size;
}

void SizeLimits::validate(const std::string& what) const {
  require(std::isfinite(min_width) && std::isfinite(max_width) && std::isfinite(min_height) &&
              std::isfinite(max_height) && min_width >= 0 && min_height >= 0 &&
              min_width <= max_width && min_height <= max_height,
          what + ": size limits must be finite with 0 <= min <= max (width " +
              std::to_string(min_width) + ".." + std::to_string(max_width) + ", height " +
              std::to_string(min_height) + ".." + std::to_string(max_height) + ")");
}

std::vector<Detection> verify_metric_size(const std::vector<Detection>& detections,
                                          const PointImage& points, const SizeLimits& limits) {
  limits.validate("verify_metric_size");
  std::vector<Detection> kept;
  for (const Detection& d : detections) {
    const auto size = measure_detection(points, d);
    if (size && size->width >= limits.min_width && size->width <= limits.max_width &&
        size->height >= limits.min_height && size->height <= limits.max_height) {
      kept.push_back(d);
    }
  }
  return kept;
}

void save_cascade(const HaarCascade& cascade, const std::string& path) {
  check_cascade(cascade, "save_cascade " + path);
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::WRITE);
  } catch (const cv::Exception& e) {
    throw Error("save_cascade: cannot write " + path + ": " + e.what());
  }
  require(fs.isOpened(), "save_cascade: cannot write " + path);
  fs << "format"
     << "kartograf_haar_cascade_v1";
  fs << "object_class" << cascade.object_class << "window" << cascade.window << "min_stddev"
     << cascade.min_stddev;
  // One row per rectangle slot: feature, x, y, w, h, weight (3 slots per feature; weight 0 unused).
  cv::Mat rects(static_cast<int>(cascade.features.size()) * 3, 5, CV_32S, cv::Scalar(0));
  for (std::size_t f = 0; f < cascade.features.size(); ++f) {
    for (int r = 0; r < cascade.features[f].rect_count; ++r) {
      const HaarRect& h = cascade.features[f].rects[static_cast<std::size_t>(r)];
      int* row = rects.ptr<int>(static_cast<int>(f) * 3 + r);
      row[0] = h.x, row[1] = h.y, row[2] = h.width, row[3] = h.height;
      row[4] = static_cast<int>(h.weight);
    }
  }
  fs << "feature_rects" << rects;
  fs << "stages"
     << "[";
  for (const CascadeStage& stage : cascade.stages) {
    cv::Mat stumps(static_cast<int>(stage.stumps.size()), 4, CV_32F);
    for (std::size_t i = 0; i < stage.stumps.size(); ++i) {
      float* row = stumps.ptr<float>(static_cast<int>(i));
      row[0] = static_cast<float>(stage.stumps[i].feature);
      row[1] = stage.stumps[i].threshold;
      row[2] = stage.stumps[i].left;
      row[3] = stage.stumps[i].right;
    }
    fs << "{"
       << "threshold" << stage.threshold << "stumps" << stumps << "}";
  }
  fs << "]";
  fs.release();
}

HaarCascade load_cascade(const std::string& path) {
  // Checked here so that a missing file is one clear Error, not also an OpenCV log line.
  require(std::filesystem::is_regular_file(path), "load_cascade: no model file " + path);
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw Error("load_cascade: cannot read " + path + ": " + e.what());
  }
  require(fs.isOpened(), "load_cascade: cannot open " + path);
  require(static_cast<std::string>(fs["format"]) == "kartograf_haar_cascade_v1",
          "load_cascade: " + path + " is not a Kartograf Haar cascade (format field)");
  HaarCascade cascade;
  cascade.object_class = static_cast<std::string>(fs["object_class"]);
  cascade.window = static_cast<int>(fs["window"]);
  cascade.min_stddev = static_cast<float>(fs["min_stddev"]);
  cv::Mat rects;
  fs["feature_rects"] >> rects;
  require(rects.empty() || (rects.cols == 5 && rects.rows % 3 == 0 && rects.type() == CV_32S),
          "load_cascade: " + path + ": feature_rects must be an n x 5 integer matrix, n % 3 == 0");
  for (int f = 0; f < rects.rows / 3; ++f) {
    HaarFeature feature;
    for (int r = 0; r < 3; ++r) {
      const int* row = rects.ptr<int>(f * 3 + r);
      if (row[4] == 0) continue;
      require(row[0] >= 0 && row[1] >= 0 && row[2] > 0 && row[3] > 0 &&
                  row[0] + row[2] <= cascade.window && row[1] + row[3] <= cascade.window,
              "load_cascade: " + path + ": feature " + std::to_string(f) +
                  " has a rectangle outside the window");
      feature.rects[static_cast<std::size_t>(feature.rect_count++)] = {
          row[0], row[1], row[2], row[3], static_cast<float>(row[4])};
    }
    cascade.features.push_back(feature);
  }
  const cv::FileNode stages = fs["stages"];
  require(stages.isSeq(), "load_cascade: " + path + ": no stages sequence");
  for (const cv::FileNode& node : stages) {
    CascadeStage stage;
    stage.threshold = static_cast<float>(node["threshold"]);
    cv::Mat stumps;
    node["stumps"] >> stumps;
    require(stumps.cols == 4 && stumps.type() == CV_32F,
            "load_cascade: " + path + ": stage stumps must be an n x 4 float matrix");
    for (int i = 0; i < stumps.rows; ++i) {
      const float* row = stumps.ptr<float>(i);
      stage.stumps.push_back({static_cast<int>(row[0]), row[1], row[2], row[3]});
    }
    cascade.stages.push_back(std::move(stage));
  }
  check_cascade(cascade, "load_cascade " + path);
  return cascade;
}

}  // namespace kartograf::semantic
