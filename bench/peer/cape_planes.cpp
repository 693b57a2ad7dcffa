// CAPE's side of the plane comparison (Proença & Gao, IROS 2018; pedropro/CAPE, MIT licence),
// built from a checkout that scripts/fetch-cape.sh makes (KARTOGRAF_CAPE_DIR), not copied here.
// Run as its own example (run_cape_offline.cpp) runs it: 20 x 20 pixel cells, planes merged up to
// 15 degrees and 50 mm apart, no cylinders; the timed call is its example's timed region: the
// cloud put in cell order (organizePointCloudByCell) and CAPE::process. CAPE takes millimetres
// (its constants are in mm), 0 where there is no depth; it finds planes in the camera frame the
// points are given in, so its normals are comparable to Kartograf's.
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include <CAPE.h>
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "peer_timing.hpp"
#include "plane_methods.hpp"

namespace kartograf::peer {
namespace {

constexpr int kCell = 20;                  // pixels, as CAPE's example
constexpr double kMergeAngle = M_PI / 12;  // 15 degrees, as CAPE's example
constexpr float kMergeDistanceMm = 50.0f;  // as CAPE's example

// CAPE's state for one image size: the detector and where each pixel goes in cell order.
struct Detector {
  Detector(int width, int height)
      : cape(height, width, kCell, kCell, false, static_cast<float>(std::cos(kMergeAngle)),
             kMergeDistanceMm),
        cell_order(height, width),
        ordered(width * height, 3) {
    const int cells_across = width / kCell;
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) {
        cell_order(r, c) = ((r / kCell) * cells_across + c / kCell) * kCell * kCell +
                           (r % kCell) * kCell + c % kCell;
      }
    }
  }
  CAPE cape;
  cv::Mat_<int> cell_order;
  Eigen::MatrixXf ordered;  // the cloud in cell order (CAPE's input)
};

// CAPE's example's organizePointCloudByCell: the columns of `cloud` moved into cell order.
void put_in_cell_order(const Eigen::MatrixXf& cloud, Detector& detector) {
  const Eigen::Index n = cloud.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    const int to = detector.cell_order(static_cast<int>(i));
    detector.ordered(to, 0) = cloud(i, 0);
    detector.ordered(to, 1) = cloud(i, 1);
    detector.ordered(to, 2) = cloud(i, 2);
  }
}

// One frame's cloud (mm, row-major pixel order, 0 where invalid) and the last call's planes.
struct Prepared {
  Eigen::MatrixXf cloud;
  cv::Mat_<unsigned char> segments;  // 0: none, 1..n: plane
  std::vector<PlaneSeg> planes;
  std::vector<CylinderSeg> cylinders;
};

Eigen::MatrixXf millimetre_cloud(const PlaneFrame& frame) {
  Eigen::MatrixXf cloud(static_cast<Eigen::Index>(frame.points.size()), 3);
  for (std::size_t i = 0; i < frame.points.size(); ++i) {
    const Point4f& p = frame.points.data()[i];
    const bool valid = is_valid(p) && p.z() > 0;
    for (int k = 0; k < 3; ++k) cloud(static_cast<Eigen::Index>(i), k) = valid ? 1000 * p[k] : 0;
  }
  return cloud;
}

PlaneOutput cape_output(const Prepared& prepared) {
  PlaneOutput out;
  out.labels = LabelImage(prepared.segments.cols, prepared.segments.rows, 0);
  for (int r = 0; r < prepared.segments.rows; ++r) {
    for (int c = 0; c < prepared.segments.cols; ++c) out.labels(c, r) = prepared.segments(r, c);
  }
  for (std::size_t k = 0; k < prepared.planes.size(); ++k) {
    const double* n = prepared.planes[k].normal;
    out.normals[static_cast<std::uint32_t>(k + 1)] = Eigen::Vector3d(n[0], n[1], n[2]);
  }
  return out;
}

}  // namespace

std::vector<PlaneMethod> cape_plane_methods() {
  auto detectors = std::make_shared<std::map<std::pair<int, int>, std::unique_ptr<Detector>>>();
  PlaneMethod method;
  method.name = "CAPE (planes)";
  method.library = "cape";
  method.threads = "single-threaded";
  method.settings =
      "CAPE as its example runs it: 20 px cells, planes merged within 15 degrees and "
      "50 mm, no cylinders; timed: organizePointCloudByCell + process";
  method.prepare = [detectors](const PlaneFrame& frame) {
    const int width = frame.points.width(), height = frame.points.height();
    if (width % kCell != 0 || height % kCell != 0) {  // CAPE needs whole cells
      throw std::invalid_argument("CAPE needs an image size that is a multiple of 20 pixels");
    }
    auto& detector = (*detectors)[{width, height}];
    if (!detector) detector = std::make_unique<Detector>(width, height);  // untimed, once
    auto prepared = std::make_shared<Prepared>();
    prepared->cloud = millimetre_cloud(frame);
    Detector* d = detector.get();
    PlaneRun run;
    // CAPE writes the labelled pixels only: zeroed once, as every call labels the same ones.
    prepared->segments = cv::Mat_<unsigned char>::zeros(height, width);
    run.call = [d, prepared]() {
      prepared->planes.clear(), prepared->cylinders.clear();
      Clock::time_point start = Clock::now();
      put_in_cell_order(prepared->cloud, *d);
      TimeParts parts{{"cell order", 1000 * seconds_since(start)}};
      start = Clock::now();
      int plane_count = 0, cylinder_count = 0;
      cv::Mat segments = prepared->segments;
      d->cape.process(d->ordered, plane_count, cylinder_count, segments, prepared->planes,
                      prepared->cylinders);
      parts.push_back({"process", 1000 * seconds_since(start)});
      return parts;
    };
    run.output = [prepared]() { return cape_output(*prepared); };
    return run;
  };
  method.another = [] { return cape_plane_methods().front(); };  // its own detectors
  return {method};
}

}  // namespace kartograf::peer
