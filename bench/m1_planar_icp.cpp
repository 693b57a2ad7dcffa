// kartograf_m1_planar_icp: the M1 paper's registration experiment (methods.md M1 steps 5-8) on
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
//   kartograf_m1_planar_icp [--sequence DIR] [--frames 25] [--gaps 1] [--points-per-plane 200]
//   e.g. the paper's second experiment: --frames 61 --gaps 1,2,3,4,5
#include <CLI/CLI.hpp>

#include <algorithm>
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
#include "kartograf/io/sequence_detect.hpp"
#include "kartograf/registration/icp.hpp"
#include "kartograf/registration/kdtree_correspondences.hpp"
#include "kartograf/segmentation/plane_extraction.hpp"
#include "kartograf/segmentation/plane_sampling.hpp"

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
};

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
    const segmentation::PlaneSet planes = extractor_.extract(prepared.points, frame.color);
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
    params.max_normal_angle_deg = 180;  // sampled plane points carry the plane's normal
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
  CLI11_PARSE(app, argc, argv);

  const compute::Context context = compute::Context::from_environment();
  const std::unique_ptr<io::Sequence> sequence = io::open_sequence(options.sequence).sequence;
  Experiment experiment(context, *sequence, options);
  std::printf("%s, frames %zu..%zu, N = %zu, %s ICP (k-d tree, %d iterations, %.2f m gate), %s\n\n",
              options.sequence.c_str(), options.first, options.first + options.frames - 1,
              options.points_per_plane,
              options.point_to_point ? "point-to-point" : "point-to-plane", options.iterations,
              options.max_distance, context.device_info().name.c_str());
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
