#include "kartograf/semantic/object_detector.hpp"
#include "kartograf/core/models.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/semantic/normals_image.hpp"

namespace kartograf::semantic {

namespace {

PointImage every_other_pixel(const PointImage& points) {
  PointImage half(points.width() / 2, points.height() / 2);
  for (int y = 0; y < half.height(); ++y)
    for (int x = 0; x < half.width(); ++x) half(x, y) = points(2 * x, 2 * y);
  return half;
}

// Points of the box's central half within a quarter of their median range of it: the object,
// not the wall or floor seen past its edges.
std::vector<Eigen::Vector3d> object_points(const PointImage& points, const Detection& box) {
  std::vector<Eigen::Vector3d> central;
  for (int y = box.y + box.height / 4; y < box.y + 3 * box.height / 4; ++y) {
    for (int x = box.x + box.width / 4; x < box.x + 3 * box.width / 4; ++x) {
      const Point4f& p = points(x, y);
      if (is_valid(p)) central.push_back(p.head<3>().cast<double>());
    }
  }
  if (central.empty()) return central;
  std::vector<double> ranges;
  for (const Eigen::Vector3d& p : central) ranges.push_back(p.norm());
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  const double median = ranges[ranges.size() / 2];
  std::erase_if(central, [&](const Eigen::Vector3d& p) {
    return std::fabs(p.norm() - median) > 0.25 * median;
  });
  return central;
}

}  // namespace

ObjectDetector::ObjectDetector(HaarCascade cascade, SizeLimits limits, ObjectDetectorParams params)
    : cascade_(std::move(cascade)), limits_(limits), params_(std::move(params)) {
  require(!cascade_.stages.empty(), "object detector: the cascade has no stage");
  limits_.validate("object detector (" + cascade_.object_class + ")");
  require(params_.max_width >= cascade_.window,
          "object detector: max_width must be at least the cascade's window");
}

SizeLimits stairs_size_limits() {
  // Stairs 0.8-1.4 m wide and 0.45-1.0 m high, seen in a square 1.1 x their larger projected
  // side (which grows with the depth of the flight at oblique views): the ground-truth squares of
  // 100 held-out views measure 0.99-1.97 m; the limits leave a margin for loose detection boxes.
  return {0.7, 2.4, 0.7, 2.4};
}

std::filesystem::path ObjectDetector::default_stairs_model_path() {
  return models_dir() / "semantic" / "stairs_cascade.yml.gz";
}

ObjectDetector ObjectDetector::stairs() {
  return ObjectDetector(load_cascade(default_stairs_model_path().string()), stairs_size_limits());
}

std::vector<ViewDetection> ObjectDetector::detect(const compute::Context& context,
                                                  const PointImage& points) const {
  PointImage scaled = points;
  int factor = 1;
  while (scaled.width() > params_.max_width) {
    scaled = every_other_pixel(scaled);
    factor *= 2;
  }
  NormalsImageParams normals;
  normals.smoothing_radius = params_.normals_smoothing_radius;
  const GrayImage gray = normals_rgb_to_gray(normals_to_rgb(
      estimate_organized_normals(context, scaled, normals), NormalEncoding::absolute));
  std::vector<ViewDetection> out;
  for (Detection box : detect_objects(cascade_, gray, params_.detection)) {
    box.x *= factor, box.y *= factor, box.width *= factor, box.height *= factor;
    box.width = std::min(box.width, points.width() - box.x);
    box.height = std::min(box.height, points.height() - box.y);
    if (verify_metric_size({box}, points, limits_).empty()) continue;
    out.push_back({box, object_points(points, box)});
  }
  return out;
}

ObjectDetection to_map_detection(const std::vector<Eigen::Vector3d>& points, SemanticClass label,
                                 std::string name) {
  require(points.size() >= 3, "detection '" + name + "': needs >= 3 points to place it, got " +
                                  std::to_string(points.size()));
  std::vector<cv::Point2f> xy;
  ObjectDetection out;
  out.label = label;
  out.name = std::move(name);
  out.z_min = out.z_max = points.front().z();
  for (const Eigen::Vector3d& p : points) {
    xy.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    out.z_min = std::min(out.z_min, p.z()), out.z_max = std::max(out.z_max, p.z());
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(xy, hull);
  require(hull.size() >= 3 && cv::contourArea(hull) > 1e-6,
          "detection '" + out.name + "': its points have no footprint (a line or a spot)");
  for (const cv::Point2f& v : hull) out.footprint.emplace_back(v.x, v.y);
  return out;
}

}  // namespace kartograf::semantic
