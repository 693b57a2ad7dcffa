// `kartograf synth`: writes a synthetic RGB-D data set with exact ground truth
// (io/synthetic_dataset.hpp). Wiring only: options in, io::write_synthetic_dataset, a summary out.
#include <chrono>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <ostream>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/outputs/synthetic_dataset.hpp"
#include "option_checks.hpp"
#include "output_transaction.hpp"

namespace kartograf::cli {

CLI::App* add_synth_command(CLI::App& app, SynthOptions& o) {
  CLI::App* synth = app.add_subcommand(
      "synth", "Write a synthetic indoor RGB-D data set (TUM layout) with exact ground truth");
  synth
      ->add_option("--out", o.out_dir,
                   "Output folder (new, empty, or an earlier run's with --force)")
      ->required();
  synth->add_option("--seed", o.seed, "World and noise seed")
      ->check(whole_number(std::numeric_limits<std::uint64_t>::max()))
      ->capture_default_str();
  synth
      ->add_option("--frames", o.frames,
                   "Number of frames (30 Hz); default 300, with --survey as many as the tour "
                   "needs to keep its per-frame limits")
      ->check(CLI::Range(1, 100000))
      ->each([&o](const std::string&) { o.frames_given = true; });
  synth->add_option("--trajectory", o.trajectory, "robot: a tour of every room; handheld: one room")
      ->capture_default_str()
      ->check(CLI::IsMember({"robot", "handheld"}));
  synth
      ->add_option("--look-around", o.look_around_deg,
                   "robot: how far the camera turns left and right inside each room [deg]")
      ->capture_default_str()
      ->check(finite_in(0.0, 170.0));
  synth->add_flag("--survey", o.survey,
                  "robot: turn once all the way round in every room and corridor pass");
  synth->add_option("--pitch", o.pitch_deg, "robot: the camera's downward pitch [deg]")
      ->capture_default_str()
      ->check(finite_in(0.0, 60.0));
  synth->add_option("--room", o.room, "handheld: the room id (default: the largest room)");
  synth
      ->add_option(
          "--width", o.intrinsics.width,
          "Image width (without --fx/--fy/--cx/--cy the Kinect's intrinsics scale with it)")
      ->capture_default_str()
      ->check(CLI::Range(1, 8192));
  synth->add_option("--height", o.intrinsics.height, "Image height")
      ->capture_default_str()
      ->check(CLI::Range(1, 8192));
  synth->add_option("--fx", o.intrinsics.fx, "Focal length x [px]")
      ->check(finite_positive())
      ->capture_default_str()
      ->each([&o](const std::string&) { o.intrinsics_given = true; });
  synth->add_option("--fy", o.intrinsics.fy, "Focal length y [px]")
      ->check(finite_positive())
      ->capture_default_str()
      ->each([&o](const std::string&) { o.intrinsics_given = true; });
  synth->add_option("--cx", o.intrinsics.cx, "Principal point x [px]")
      ->check(finite_number())
      ->capture_default_str()
      ->each([&o](const std::string&) { o.intrinsics_given = true; });
  synth->add_option("--cy", o.intrinsics.cy, "Principal point y [px]")
      ->check(finite_number())
      ->capture_default_str()
      ->each([&o](const std::string&) { o.intrinsics_given = true; });
  synth->add_flag("--no-noise", o.no_noise,
                  "Exact depth (to 0.2 mm) with every return, clean colour");
  synth->add_flag("--force", o.force, "Replace the folder of an earlier run as a whole");
  synth->add_option("--threads", o.threads, "Worker threads (0: all cores)")
      ->check(whole_number(4096))
      ->capture_default_str();
  return synth;
}

int run_synth_command(const SynthOptions& o, std::ostream& out, std::ostream& err) {
  OutputFolder folder("synth", o.out_dir, o.force,
                      {"rgb", "depth", "gt", "rgb.txt", "depth.txt", "groundtruth.txt",
                       "camera_intrinsics.json", "world.json", "floor_plan.yaml", "floor_plan.pgm",
                       "floor_plan.png", "floor_plan_gt_segmentation.png", "rooms.png",
                       "semantic_grid.png", "laser_scan.pcd", "preview.png"});
  io::SyntheticDatasetParams options;
  options.seed = o.seed;
  options.frames = o.survey && !o.frames_given ? 0 : o.frames;
  options.trajectory = o.trajectory == "handheld" ? io::SyntheticTrajectory::handheld
                                                  : io::SyntheticTrajectory::robot;
  options.handheld_room = static_cast<Label>(o.room);
  options.tour.look_around_deg = o.look_around_deg;
  options.tour.pitch_deg = o.pitch_deg;
  options.tour.survey = o.survey;
  require(o.room >= 0 && o.room <= 65535, "--room must be a room id");
  options.intrinsics = o.intrinsics;
  if (!o.intrinsics_given) {
    // The Kinect's 525 px focal length at 640 wide, scaled to the image; principal point centred.
    options.intrinsics.fx = options.intrinsics.fy = 525.0 * o.intrinsics.width / 640.0;
    options.intrinsics.cx = (o.intrinsics.width - 1) / 2.0;
    options.intrinsics.cy = (o.intrinsics.height - 1) / 2.0;
  }
  options.noise = o.no_noise ? synth::NoiseModel::none() : synth::NoiseModel::kinect();
  options.force = o.force;
  options.threads = o.threads;
  options.progress = [&err](const std::string& line) {
    err << "synth: " << line << std::endl;
    exit_if_interrupted();  // the frames are written while they are rendered: stop between them
  };

  const auto start = std::chrono::steady_clock::now();
  const io::SyntheticDatasetSummary summary = [&] {
    const InterruptsDeferred writing;
    return io::write_synthetic_dataset(folder.dir(), options);
  }();
  folder.commit();
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;

  const synth::World& world = summary.world;
  out << "synthetic data set: " << o.out_dir.string() << "\n"
      << "  seed " << o.seed << ", " << world.rooms.size() << " rooms (corridor included), "
      << world.doorways.size() << " doorways, " << world.furniture.size()
      << " pieces of furniture, " << world.door_leaves.size() << " door leaves, "
      << world.planes.size() << " planes\n"
      << "  " << summary.trajectory.size() << " frames (" << o.trajectory << "), "
      << o.intrinsics.width << "x" << o.intrinsics.height << ", noise "
      << (o.no_noise ? "off" : "kinect") << "\n"
      << "  " << summary.files << " files in " << std::fixed << std::setprecision(2)
      << elapsed.count() << " s\n";
  return 0;
}

}  // namespace kartograf::cli
