// kartograf_peer_bench: Kartograf against Open3D and PCL on the same inputs, in one run
// (docs/benchmarks.md holds the results): registration (issue 4, part 6) and plane segmentation
// (issue 5, part 8; plane_bench.hpp). --suite picks one of the two.
//
// Registration:
//   pairs   7-Scenes RedKitchen frames (i + 1, i) and (i + 5, i) for several i, and the same on a
//           synthetic hand-held sequence. Every method gets the same inputs: RGB-D frames for the
//           odometry methods; clouds cut once by Kartograf (valid points with organized normals and
//           colours, full and voxel-downsampled to ~20k points) for the cloud ICPs, converted to
//           each library's types outside the timing.
//   timing  per method and pair: one untimed warm-up call on the first pair, then calls until
//           --min-time seconds have passed (at least 1, at most --max-calls); the pair's time is
//           their median, the method's time the median over pairs. Wall clock, steady_clock.
//   chain   frame k aligned to frame k - 1 over a whole sequence (Kartograf's two-frame ICP, its
//           full RgbdOdometry with the motion model and re-estimation, and Open3D's RGB-D odometry
//           in lockstep, each frame read once), ATE and RPE against the ground truth
//           (eval::evaluate_trajectory, SE(3) alignment).
// Threads are whatever the environment pins: OMP_NUM_THREADS (Open3D's OpenMP loops) and
// KARTOGRAF_CPU_THREADS (Kartograf's CPU loops; 1 when unset); both are printed.
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "kartograf/core/error.hpp"
#include "kartograf/eval/trajectory_metrics.hpp"
#include "kartograf/formats/tum.hpp"
#include "peer_methods.hpp"
#include "peer_report.hpp"
#include "peer_timing.hpp"
#include "plane_bench.hpp"

namespace kartograf::peer {
namespace {

struct Options {
  std::string suite = "all";  // "registration", "planes" or "all"
  std::filesystem::path seven_scenes;
  std::filesystem::path synthetic;
  int synthetic_frames = 60;
  std::vector<std::size_t> seven_scenes_starts = {0, 60, 120, 180, 240};
  std::vector<std::size_t> synthetic_starts = {0, 15, 30};
  std::vector<int> gaps = {1, 5};
  std::size_t target_points = 20000;
  TimingOptions timing;
  bool chain = true;
  bool device_backends = true;
  bool details = false;                // every pair's errors and time on stderr
  std::string only;                    // run only methods whose name contains this
  std::filesystem::path trajectories;  // write the chained trajectories here (TUM format)
  PlaneBenchOptions planes;            // its 7-Scenes folder, timing, only, ... come from above
};

std::vector<MethodOutcome> run_pairs(const std::vector<Method>& methods,
                                     const std::vector<FramePair>& pairs, const Options& options) {
  std::vector<MethodOutcome> outcomes;
  for (const Method& method : methods) {
    std::cerr << "  " << method.name << std::flush;
    MethodOutcome outcome{&method, {}};
    method.prepare(pairs.front())();  // warm-up: lazy initialisation, first allocations
    for (const FramePair& pair : pairs) {
      CallTimes times;
      const std::vector<Estimate> estimates =
          time_calls(method.prepare(pair), options.timing, times);
      outcome.pairs.push_back(
          score(pair, estimates.back(), std::move(times.seconds), std::move(times.cpu_seconds)));
    }
    std::cerr << ": " << 1000 * outcome.median_seconds() << " ms\n";
    outcomes.push_back(std::move(outcome));
  }
  return outcomes;
}

struct Tracker {
  Tracker(std::string name, std::string threads, std::unique_ptr<OdometryFrontEnd> odometry)
      : name(std::move(name)), threads(std::move(threads)), odometry(std::move(odometry)) {}
  std::string name;
  std::string threads;
  std::unique_ptr<OdometryFrontEnd> odometry;
  Trajectory trajectory;
  std::vector<double> seconds;
  std::size_t failures = 0;
};

std::vector<ChainOutcome> run_chain(const Dataset& dataset, const Options& options) {
  std::vector<Tracker> trackers;
  trackers.emplace_back(kKartografOdometry, kartograf_threads(),
                        kartograf_odometry_factory()(dataset));
  trackers.emplace_back(kKartografRgbdOdometry, kartograf_threads(),
                        kartograf_rgbd_odometry_factory()(dataset));
  trackers.emplace_back("open3d RGB-D odometry, hybrid term", openmp_threads(),
                        open3d_odometry_factory()(dataset));
  Trajectory ground_truth;
  for (std::size_t k = 0; k < dataset.size(); ++k) {
    const Frame frame = dataset.frame(k);
    const double timestamp = static_cast<double>(k) / 30.0;
    ground_truth.push_back({timestamp, frame.pose});
    for (Tracker& tracker : trackers) {
      if (k == 0) {
        tracker.odometry->set_reference(frame);
        tracker.trajectory.push_back({timestamp, frame.pose});
        continue;
      }
      const Clock::time_point start = Clock::now();
      Estimate estimate = tracker.odometry->track(frame);
      tracker.seconds.push_back(seconds_since(start));
      tracker.odometry->advance();
      if (!estimate.success) {
        ++tracker.failures;
        estimate.source_to_target = Eigen::Isometry3d::Identity();
      }
      tracker.trajectory.push_back(
          {timestamp, tracker.trajectory.back().pose * estimate.source_to_target});
    }
    if (k % 50 == 49) std::cerr << "  " << dataset.name << " frame " << k + 1 << "\n";
  }
  std::vector<ChainOutcome> outcomes;
  for (Tracker& tracker : trackers) {
    const eval::MatchedPoses matched{ground_truth, tracker.trajectory};
    const eval::TrajectoryEvaluation evaluation =
        eval::evaluate_trajectory(matched, eval::Alignment::se3, eval::RpeParams{});
    outcomes.push_back({dataset.name, tracker.name, tracker.threads, dataset.size(),
                        1000 * median(tracker.seconds), evaluation.ate.translation_m.rmse,
                        1000 * evaluation.rpe.translation_m.rmse, evaluation.rpe.rotation_deg.rmse,
                        tracker.failures});
    if (!options.trajectories.empty()) {
      std::filesystem::create_directories(options.trajectories);
      const std::string stem = dataset.name + "_" +
                               (tracker.name.rfind("open3d", 0) == 0     ? "open3d"
                                : tracker.name == kKartografRgbdOdometry ? "kartograf_rgbd_odometry"
                                                                         : "kartograf");
      io::write_tum_trajectory(options.trajectories / (stem + ".txt"), tracker.trajectory);
      io::write_tum_trajectory(options.trajectories / (dataset.name + "_groundtruth.txt"),
                               ground_truth);
    }
  }
  return outcomes;
}

std::size_t median_size(const std::vector<FramePair>& pairs, bool full) {
  std::vector<double> sizes;
  for (const FramePair& pair : pairs) {
    for (const FrameClouds* clouds : {&pair.source_clouds, &pair.target_clouds}) {
      sizes.push_back(static_cast<double>(full ? clouds->full.size() : clouds->sampled.size()));
    }
  }
  return static_cast<std::size_t>(median(sizes));
}

std::vector<Method> all_methods(const Options& options, const CloudIcpSettings& settings) {
  std::vector<Method> methods;
  for (auto&& list : {kartograf_methods(settings, options.device_backends),
                      open3d_methods(settings), pcl_methods(settings)}) {
    for (const Method& method : list) {
      if (options.only.empty() || method.name.find(options.only) != std::string::npos ||
          method.name == kKartografOdometry) {
        methods.push_back(method);
      }
    }
  }
  return methods;
}

void run_registration(const Options& options) {
  const CloudIcpSettings settings;
  std::cout << "\n# Registration\n\n"
            << "- cloud ICP (all libraries): max correspondence distance " << settings.max_distance
            << " m, at most " << settings.max_iterations
            << " iterations, identity start; odometry: each library's defaults, identity start, "
               "depth "
            << kMinDepthMetres << "-" << kMaxDepthMetres << " m\n"
            << "- timing: per pair the median of 1-" << options.timing.max_calls << " calls (until "
            << options.timing.min_time
            << " s have passed) after one warm-up call, per method the median over pairs; wall "
               "clock and process CPU time (all threads); ratio = method time / Kartograf time\n";

  std::vector<Dataset> datasets;
  std::vector<std::vector<std::size_t>> starts;
  if (!options.seven_scenes.empty()) {
    datasets.push_back(open_seven_scenes_dataset(options.seven_scenes));
    starts.push_back(options.seven_scenes_starts);
  }
  if (!options.synthetic.empty()) {
    if (!std::filesystem::exists(options.synthetic / "rgb.txt")) {
      std::cerr << "writing a synthetic sequence into " << options.synthetic << "\n";
      write_synthetic_sequence(options.synthetic, options.synthetic_frames);
    }
    datasets.push_back(open_synthetic_dataset(options.synthetic));
    starts.push_back(options.synthetic_starts);
  }
  require(!datasets.empty(), "no data set: give --seven-scenes and/or --synthetic");

  const std::vector<Method> methods = all_methods(options, settings);
  std::vector<ChainOutcome> chains;
  for (std::size_t d = 0; d < datasets.size(); ++d) {
    const Dataset& dataset = datasets[d];
    std::cerr << "preparing " << dataset.name << " pairs\n";
    const CloudMaker clouds(dataset, options.target_points);
    const std::vector<FramePair> pairs = make_pairs(dataset, clouds, starts[d], options.gaps);
    std::cout << "\n## " << dataset.name << ": " << pairs.size() << " pairs\n\n"
              << dataset.note << ". Pairs (target -> source):";
    for (const FramePair& pair : pairs)
      std::cout << " " << pair.label().substr(dataset.name.size() + 1);
    std::cout << ". Clouds: median " << median_size(pairs, true) << " points full, "
              << median_size(pairs, false) << " after " << std::fixed << std::setprecision(2)
              << 100 * clouds.voxel_size() << std::defaultfloat << " cm voxels.\n\n";
    const std::vector<MethodOutcome> outcomes = run_pairs(methods, pairs, options);
    print_pair_table(std::cout, outcomes);
    if (options.details) print_pair_details(std::cerr, outcomes);
    std::cout.flush();
    if (options.chain) {
      std::cerr << "chaining " << dataset.name << " (" << dataset.size() << " frames)\n";
      const auto outcomes = run_chain(dataset, options);
      chains.insert(chains.end(), outcomes.begin(), outcomes.end());
    }
  }
  if (!chains.empty()) {
    std::cout << "\n## Chained odometry (frame k to k - 1 from the identity, whole sequence)\n\n";
    print_chain_table(std::cout, chains);
  }
}

void run_planes(const Options& options) {
  PlaneBenchOptions planes = options.planes;
  planes.seven_scenes = options.seven_scenes;
  planes.device_backends = options.device_backends;
  planes.only = options.only;
  planes.details = options.details;
  planes.timing = options.timing;
  for (auto&& list : {pcl_plane_methods(), open3d_plane_methods(planes.ransac_max_planes)})
    planes.peers.insert(planes.peers.end(), list.begin(), list.end());
  run_plane_bench(planes, std::cout);
}

int run(const Options& options) {
  const Clock::time_point start = Clock::now();
  std::cout << "# Kartograf peer benchmark\n\n"
            << "- machine: " << cpu_model() << ", " << std::thread::hardware_concurrency()
            << " cores; load average at start " << load_average() << "\n"
            << "- Open3D " << open3d_version() << ", PCL " << pcl_version() << "\n"
            << "- threads: " << kartograf_threads() << ", " << openmp_threads()
            << ", PCL single-threaded\n";
  if (options.suite != "planes") run_registration(options);
  if (options.suite != "registration") run_planes(options);
  std::cout << "\nload average at the end " << load_average() << "; run took "
            << std::lround(seconds_since(start)) << " s\n";
  return 0;
}

}  // namespace
}  // namespace kartograf::peer

int main(int argc, char** argv) {
  kartograf::peer::Options options;
  CLI::App app{
      "Kartograf against Open3D and PCL on the same frames: registration and plane "
      "segmentation (docs/benchmarks.md)"};
  const char* data = std::getenv("KARTOGRAF_DATA_DIR");
  const std::filesystem::path data_dir = data && *data ? data : KARTOGRAF_DEFAULT_DATA_DIR;
  options.seven_scenes = data_dir / "7scenes_redkitchen";
  app.add_option("--seven-scenes", options.seven_scenes, "7-Scenes folder ('' to skip)")
      ->capture_default_str();
  options.synthetic = std::filesystem::temp_directory_path() / "kartograf-peer-synthetic";
  app.add_option("--synthetic", options.synthetic,
                 "Synthetic TUM folder (kartograf synth); written there when it has no rgb.txt "
                 "('' to skip)")
      ->capture_default_str();
  app.add_option("--synthetic-frames", options.synthetic_frames, "Frames when writing it")
      ->capture_default_str();
  app.add_option("--suite", options.suite, "What to compare")
      ->capture_default_str()
      ->check(CLI::IsMember({"all", "registration", "planes"}));
  app.add_option("--min-time", options.timing.min_time,
                 "Seconds of calls per method and pair (or frame)")
      ->capture_default_str();
  app.add_option("--max-calls", options.timing.max_calls,
                 "Most timed calls per method and pair (or frame)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  options.planes.mosd = data_dir / "pcl_mosd";
  app.add_option("--mosd", options.planes.mosd, "Planes: PCL's mOSD folder ('' to skip)")
      ->capture_default_str();
  app.add_option("--plane-synthetic-frames", options.planes.synthetic_frames,
                 "Planes: synthetic robot-tour frames with exact plane ids (0 to skip)")
      ->capture_default_str()
      ->check(CLI::Range(0, 290));
  app.add_option("--plane-seven-scenes-frames", options.planes.seven_scenes_frames,
                 "Planes: 7-Scenes frame indices")
      ->capture_default_str();
  app.add_option("--plane-overlays", options.planes.overlays,
                 "Planes: write every method's planes over every frame here (PNG)");
  app.add_option("--ransac-max-planes", options.planes.ransac_max_planes,
                 "Planes: the most planes Open3D's SegmentPlane loop takes per frame")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app.add_flag("!--no-chain", options.chain, "Skip the chained trajectories");
  app.add_flag("!--no-device-backends", options.device_backends,
               "Kartograf on the CPU backend only");
  app.add_flag("--details", options.details, "Every pair's (frame's) errors and time on stderr");
  app.add_option("--only", options.only, "Only methods whose name contains this");
  app.add_option("--trajectories", options.trajectories,
                 "Write the chained trajectories here (TUM), for `kartograf eval traj`");
  CLI11_PARSE(app, argc, argv);
  try {
    return kartograf::peer::run(options);
  } catch (const std::exception& error) {
    std::cerr << "kartograf_peer_bench: " << error.what() << "\n";
    return 1;
  }
}
