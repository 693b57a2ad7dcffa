// kartograf_m1_planar_icp: the M1 paper's registration experiment (docs/methods.md M1 steps 5-8) on
// real frames. Frames f0, f0 + gap, f0 + 2 gap, ... of a sequence are registered frame to frame
// and chained twice:
//   planar     plane extraction (segmentation/plane_extraction.hpp), N points drawn on each plane
//              (plane_sampling.hpp), ICP on those points;
//   all-point  ICP on every valid point of the frames (the paper's reference model).
// Both use the same single-level k-d tree ICP (point-to-plane by default: plane normals for the
// planar points, estimated normals for all points). Per gap the program prints the median time
// per pair of each method (back-projection excluded: both need it), the speed-up, the model error
// (the paper's comparison of the two maps: RMS distance between each frame's points placed by
// the planar poses and by the all-point poses, over every frame) and both ATEs against the
// ground truth.
//
// The planar method's segments come from the Lab region growing and merging (default) or, for
// the paper's baselines (Tables 3-9), from K-Means, SOM or Fuzzy C-Means clustering of the 6-D
// features with one plane fitted per cluster; the clustering time is reported per frame.
// --tables prints the paper's Tables 1-2 instead: segments per Lab threshold (the paper's untiled
// growing and the tiled one) and planes per Lab threshold and normal angle, means over the frames.
//
//   kartograf_m1_planar_icp [--sequence DIR] [--frames 25] [--gaps 1] [--points-per-plane 200]
//                           [--segmentation lab|kmeans|som|fcm --k 30 --feature-stride 2]
//   e.g. the paper's second experiment: --frames 61 --gaps 1,2,3,4,5
//        Tables 1-2 on 10 frames: --tables --frames 10
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/geometry/normals.hpp"
#include "kartograf/geometry/subsample.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kartograf/segmentation/clustering_features.hpp"
#include "kartograf/segmentation/fuzzy_cmeans.hpp"
#include "kartograf/segmentation/kmeans.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/segmentation/plane_sampling.hpp"
#include "kartograf/segmentation/som.hpp"

namespace kartograf {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

struct Options {
  std::string sequence = KARTOGRAF_DEFAULT_DATA_DIR "/7scenes_redkitchen";
  std::size_t first = 0;
  std::size_t frames = 25;
  std::vector<int> gaps{1};
  std::size_t points_per_plane = 200;
  bool point_to_point = false;
  double max_distance = 0.1;
  int iterations = 30;
  double max_normal_angle_deg =
      30;  // pairs whose normals differ more are rejected (the ICP default)
  std::string segmentation = "lab";  // lab | kmeans | som | fcm
  std::uint32_t k = 30;              // clusters of the baselines
  int feature_stride = 2;            // baselines: cluster 1 pixel in stride^2, label all
  bool tables = false;
};

// The frame's planes by the clustering baseline named in the options: one plane per cluster.
segmentation::PlaneSet clustered_planes(const PointImage& points, const RgbImage& color,
                                        const Options& options) {
  segmentation::FeatureParams feature_params;
  feature_params.stride = options.feature_stride;
  const segmentation::ClusteringFeatures features =
      segmentation::make_clustering_features(points, color, feature_params);
  segmentation::ClusteringResult result;
  if (options.segmentation == "kmeans") {
    result = segmentation::kmeans(features, {options.k});
  } else if (options.segmentation == "som") {
    segmentation::SomParams params;
    params.k = options.k;
    result = segmentation::som(features, params);
  } else {
    segmentation::FuzzyCMeansParams params;
    params.k = options.k;
    result = segmentation::fuzzy_cmeans(features, params);
  }
  return segmentation::fit_segment_planes(
      points, segmentation::label_all_pixels(points, color, features, result), options.k, 100);
}

// A frame as both methods need it: its points, the planar sample and the full cloud.
struct PreparedFrame {
  PointImage points;
  geometry::DeviceCloud planar, full;
  double planar_seconds = 0;  // plane extraction + sampling
  double full_seconds = 0;    // normals + cloud
  std::size_t plane_count = 0;
};

PointCloud valid_cloud(const PointImage& points, const NormalImage& normals) {
  PointCloud cloud;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point4f& p = points.data()[i];
    const Point4f& n = normals.data()[i];
    if (!p.head<3>().allFinite() || !n.head<3>().allFinite()) continue;
    cloud.points.push_back(p.head<3>());
    cloud.normals.push_back(n.head<3>());
  }
  return cloud;
}

class Experiment {
 public:
  Experiment(const compute::Context& context, const io::Sequence& sequence, const Options& options)
      : context_(&context),
        sequence_(&sequence),
        options_(options),
        extractor_(context, sequence.intrinsics()),
        engine_(context, icp_params(options),
                std::make_unique<registration::KdTreeCorrespondences>(context)) {
    range_.units_per_metre = sequence.depth_units_per_metre();
  }

  PreparedFrame prepare(std::size_t index) {
    const io::RgbdFrame frame = sequence_->frame(index);
    require(frame.pose.has_value(), "frame " + std::to_string(index) + " has no ground truth");
    truth_.push_back(*frame.pose);
    PreparedFrame prepared;
    prepared.points =
        geometry::backproject(*context_, frame.depth, sequence_->intrinsics(), range_);

    Clock::time_point start = Clock::now();
    const segmentation::PlaneSet planes =
        options_.segmentation == "lab" ? extractor_.extract(prepared.points, frame.color)
                                       : clustered_planes(prepared.points, frame.color, options_);
    const PointCloud sample = segmentation::sample_plane_points(
        prepared.points, nullptr, planes, {options_.points_per_plane, index + 1});
    prepared.planar = geometry::DeviceCloud::from_host(*context_, sample);
    prepared.planar_seconds = seconds_since(start);
    prepared.plane_count = planes.planes.size();

    start = Clock::now();
    const NormalImage normals = geometry::estimate_normals(*context_, prepared.points);
    prepared.full =
        geometry::DeviceCloud::from_host(*context_, valid_cloud(prepared.points, normals));
    prepared.full_seconds = seconds_since(start);
    return prepared;
  }

  // source-to-target and the seconds ICP took.
  std::pair<Eigen::Isometry3d, double> align(const geometry::DeviceCloud& source,
                                             const geometry::DeviceCloud& target) {
    const registration::CloudView s{&source.points, &source.normals, nullptr, std::nullopt};
    const registration::CloudView t{&target.points, &target.normals, nullptr, std::nullopt};
    const Clock::time_point start = Clock::now();
    const registration::IcpResult result = engine_.align(std::span(&s, 1), std::span(&t, 1));
    return {result.source_to_target, seconds_since(start)};
  }

  const std::vector<Eigen::Isometry3d>& truth() const { return truth_; }
  void reset() { truth_.clear(); }

 private:
  static registration::IcpParams icp_params(const Options& options) {
    registration::IcpParams params;
    params.metric = options.point_to_point ? registration::ErrorMetric::point_to_point
                                           : registration::ErrorMetric::point_to_plane;
    params.max_normal_angle_deg = options.max_normal_angle_deg;
    params.levels = {{options.iterations, 1, options.max_distance, options.max_distance, 0}};
    return params;
  }

  const compute::Context* context_;
  const io::Sequence* sequence_;
  Options options_;
  geometry::DepthRange range_;
  segmentation::PlaneExtractor extractor_;
  registration::IcpEngine engine_;
  std::vector<Eigen::Isometry3d> truth_;
};

double ate_cm(const std::vector<Eigen::Isometry3d>& truth,
              const std::vector<Eigen::Isometry3d>& estimate) {
  eval::MatchedPoses matched;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    matched.ground_truth.push_back({double(i), truth[i]});
    matched.estimate.push_back({double(i), estimate[i]});
  }
  return 100 * eval::compute_ate(matched, eval::Alignment::se3).translation_m.rmse;
}

// RMS over frames and a grid of their valid points of |T_a p - T_b p|: how far apart the two maps
// place the same surfaces.
double model_error_cm(const std::vector<PointImage>& frames,
                      const std::vector<Eigen::Isometry3d>& a,
                      const std::vector<Eigen::Isometry3d>& b) {
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    for (std::size_t i = 0; i < frames[f].size(); i += 97) {
      const Eigen::Vector3d p = frames[f].data()[i].head<3>().cast<double>();
      if (!p.allFinite()) continue;
      sum += (a[f] * p - b[f] * p).squaredNorm();
      ++count;
    }
  }
  return count ? 100 * std::sqrt(sum / double(count)) : 0;
}

void run_gap(Experiment& experiment, const Options& options, int gap) {
  experiment.reset();
  std::vector<PointImage> frames;
  std::vector<Eigen::Isometry3d> planar{Eigen::Isometry3d::Identity()};
  std::vector<Eigen::Isometry3d> all{Eigen::Isometry3d::Identity()};
  std::vector<double> planar_seconds, all_seconds;
  std::vector<double> plane_counts;
  PreparedFrame previous;
  const std::size_t count = (options.frames - 1) / std::size_t(gap) + 1;
  for (std::size_t k = 0; k < count; ++k) {
    PreparedFrame current = experiment.prepare(options.first + k * std::size_t(gap));
    plane_counts.push_back(double(current.plane_count));
    if (k > 0) {
      const auto [planar_motion, planar_icp] = experiment.align(current.planar, previous.planar);
      const auto [all_motion, all_icp] = experiment.align(current.full, previous.full);
      planar.push_back(planar.back() * planar_motion);
      all.push_back(all.back() * all_motion);
      planar_seconds.push_back(current.planar_seconds + planar_icp);
      all_seconds.push_back(current.full_seconds + all_icp);
    }
    std::cerr << "  gap " << gap << ": frame " << k + 1 << "/" << count << "\r" << std::flush;
    frames.push_back(std::move(current.points));
    previous = std::move(current);
  }
  std::cerr << "\n";
  const std::vector<Eigen::Isometry3d>& truth = experiment.truth();
  const double planar_ms = 1000 * median(planar_seconds), all_ms = 1000 * median(all_seconds);
  std::printf("| %d | %zu | %.0f | %.1f | %.1f | %.0f %% | %.2f | %.2f | %.2f |\n", gap, count,
              median(plane_counts), planar_ms, all_ms, 100 * (1 - planar_ms / all_ms),
              model_error_cm(frames, planar, all), ate_cm(truth, planar), ate_cm(truth, all));
  std::fflush(stdout);
}

double mean(const std::vector<double>& values) {
  double sum = 0;
  for (const double v : values) sum += v;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

// The paper's Tables 1-2 on frames first .. first + frames - 1.
void print_tables(const compute::Context& context, const io::Sequence& sequence,
                  const Options& options) {
  geometry::DepthRange range;
  range.units_per_metre = sequence.depth_units_per_metre();
  const std::vector<float> thresholds{10, 15, 20, 25, 30};
  const std::vector<double> angles{15, 30, 45, 60};
  // [threshold] -> per frame: untiled segments, ms; tiled segments, ms.
  std::vector<std::array<std::vector<double>, 4>> growing(thresholds.size());
  // [threshold][angle] -> per frame: merged planes, planes >= min_plane_pixels, ms.
  std::vector<std::vector<std::array<std::vector<double>, 3>>> merging(
      thresholds.size(), std::vector<std::array<std::vector<double>, 3>>(angles.size()));
  for (std::size_t f = options.first; f < options.first + options.frames; ++f) {
    const io::RgbdFrame frame = sequence.frame(f);
    const PointImage points =
        geometry::backproject(context, frame.depth, sequence.intrinsics(), range);
    const segmentation::LabCodeImage lab = segmentation::to_lab_codes(frame.color);
    for (std::size_t t = 0; t < thresholds.size(); ++t) {
      segmentation::RegionGrowingParams paper;
      paper.lab_threshold = thresholds[t];
      segmentation::RegionGrowingParams tiled = segmentation::PlaneExtractionParams{}.growing;
      tiled.lab_threshold = thresholds[t];
      segmentation::SegmentLabelImage labels;
      for (const auto& [params, column] : {std::pair{paper, 0}, std::pair{tiled, 2}}) {
        const Clock::time_point start = Clock::now();
        const std::uint32_t count = segmentation::grow_regions(lab, points, params, labels);
        growing[t][column + 1].push_back(1000 * seconds_since(start));
        growing[t][column].push_back(count);
      }
      for (std::size_t a = 0; a < angles.size() && t > 0; ++a) {
        segmentation::PlaneExtractionParams params;
        params.growing.lab_threshold = thresholds[t];
        params.merge.max_normal_angle_deg = angles[a];
        segmentation::PlaneExtractor extractor(context, sequence.intrinsics(), params);
        const segmentation::PlaneSet set = extractor.extract(points, frame.color);
        merging[t][a][0].push_back(set.merged_count);
        merging[t][a][1].push_back(static_cast<double>(set.planes.size()));
        merging[t][a][2].push_back(set.timings.total());
      }
    }
    std::cerr << "  frame " << f - options.first + 1 << "/" << options.frames << "\r" << std::flush;
  }
  std::cerr << "\n";
  const int paper_segments[] = {8115, 5130, 3520, 2719, 2071};
  std::printf(
      "Table 1: segments per Lab threshold (means over %zu frames; the paper: NYU-Depth v2, "
      "561x427, MATLAB)\n\n| Lab threshold | paper: segments | untiled (the paper's growing) "
      "| ms | tiled 16 px, 2 %% depth jump | ms |\n|---:|---:|---:|---:|---:|---:|\n",
      options.frames);
  for (std::size_t t = 0; t < thresholds.size(); ++t) {
    std::printf("| %.0f | %d | %.0f | %.1f | %.0f | %.1f |\n", thresholds[t], paper_segments[t],
                mean(growing[t][0]), mean(growing[t][1]), mean(growing[t][2]), mean(growing[t][3]));
  }
  std::printf(
      "\nTable 2: planes per Lab threshold and normal angle (merged planes / planes of at least "
      "300 pixels; the paper: ~417, 282, 214, 172 planes for thresholds 15-30)\n\n| Lab "
      "threshold |");
  for (const double a : angles) std::printf(" %.0f deg |", a);
  std::printf(" ms (30 deg) |\n|---:|");
  for (std::size_t a = 0; a < angles.size(); ++a) std::printf("---:|");
  std::printf("---:|\n");
  for (std::size_t t = 1; t < thresholds.size(); ++t) {
    std::printf("| %.0f |", thresholds[t]);
    for (std::size_t a = 0; a < angles.size(); ++a)
      std::printf(" %.0f / %.0f |", mean(merging[t][a][0]), mean(merging[t][a][1]));
    std::printf(" %.1f |\n", mean(merging[t][1][2]));
  }
}

int run(int argc, char** argv) {
  Options options;
  CLI::App app{"The M1 paper's planar-ICP vs all-point-ICP experiment"};
  app.add_option("--sequence", options.sequence, "RGB-D sequence folder with ground truth");
  app.add_option("--first", options.first, "First frame");
  app.add_option("--frames", options.frames, "Frames spanned (every gap-th is used)")
      ->check(CLI::Range(2, 100000));
  app.add_option("--gaps", options.gaps, "Frame gaps, e.g. 1,2,3,4,5")->delimiter(',');
  app.add_option("--points-per-plane", options.points_per_plane, "The paper's N");
  app.add_flag("--point-to-point", options.point_to_point, "Point-to-point ICP (default: plane)");
  app.add_option("--max-distance", options.max_distance, "ICP pair gate [m]");
  app.add_option("--iterations", options.iterations, "ICP iterations");
  app.add_option("--max-normal-angle", options.max_normal_angle_deg,
                 "Normal gate of the pairs [deg] (>= 180: off)");
  app.add_option("--segmentation", options.segmentation, "Planes from: lab | kmeans | som | fcm")
      ->check(CLI::IsMember({"lab", "kmeans", "som", "fcm"}));
  app.add_option("--k", options.k, "Clusters of the baselines")->check(CLI::Range(1, 100000));
  app.add_option("--feature-stride", options.feature_stride,
                 "Baselines: cluster the pixels on a stride grid, then label every pixel")
      ->check(CLI::Range(1, 64));
  app.add_flag("--tables", options.tables, "Print the paper's Tables 1-2 instead");
  CLI11_PARSE(app, argc, argv);

  const compute::Context context = compute::Context::from_environment();
  const std::unique_ptr<io::Sequence> sequence = io::open_sequence(options.sequence).sequence;
  if (options.tables) {
    print_tables(context, *sequence, options);
    return 0;
  }
  Experiment experiment(context, *sequence, options);
  const std::string planes = options.segmentation == "lab"
                                 ? std::string("Lab region growing + merging")
                                 : options.segmentation + " k = " + std::to_string(options.k) +
                                       ", features 1 in " + std::to_string(options.feature_stride) +
                                       "^2";
  std::printf(
      "%s, frames %zu..%zu, planes: %s, N = %zu, %s ICP (k-d tree, %d iterations, %.2f m "
      "gate), %s\n\n",
      options.sequence.c_str(), options.first, options.first + options.frames - 1, planes.c_str(),
      options.points_per_plane, options.point_to_point ? "point-to-point" : "point-to-plane",
      options.iterations, options.max_distance, context.device_info().name.c_str());
  std::printf(
      "| gap | frames | planes/frame | planar ms/pair | all-point ms/pair | speed-up | model error "
      "(cm) | planar ATE (cm) | all-point ATE (cm) "
      "|\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const int gap : options.gaps) {
    require(gap >= 1, "--gaps: every gap must be >= 1");
    run_gap(experiment, options, gap);
  }
  return 0;
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  try {
    return kartograf::run(argc, argv);
  } catch (const std::exception& error) {
    std::cerr << "kartograf_m1_planar_icp: " << error.what() << "\n";
    return 1;
  }
}
