// `kartograf planes INPUT --out DIR`: plane extraction (segmentation::PlaneExtractor) of an
// organized PCD, an RGB-D frame (depth PNG + --color; in the cells mode colour is optional), or
// the frames of a sequence folder. Per frame: labels.png (16-bit plane id, 0 = none),
// segmentation.png (planes over the dimmed image, for people), planes.json and planes.ply (the
// plane points in their colours); one summary line per frame on stdout. A sequence writes each
// frame to DIR/<frame number>/ and DIR/summary.json. Wiring only.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "backend_option.hpp"
#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/pcd.hpp"
#include "kartograf/formats/ply.hpp"
#include "kartograf/formats/sequence.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/formats/text_file.hpp"
#include "kartograf/geometry/backproject.hpp"
#include "kartograf/outputs/plane_io.hpp"
#include "kartograf/outputs/plane_run.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"
#include "option_checks.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

namespace {

namespace fs = std::filesystem;

// One frame to extract planes from.
struct PlaneInput {
  std::string name;  // for messages and planes.json
  PointImage points;
  RgbImage color;
  PinholeIntrinsics intrinsics;
};

segmentation::PlaneExtractionParams extraction_params(const PlanesOptions& o) {
  segmentation::PlaneExtractionParams params;
  params.growing.lab_threshold = static_cast<float>(o.lab_threshold);
  params.merge.max_normal_angle_deg = o.normal_angle_deg;
  params.min_plane_pixels = o.min_plane_pixels;
  params.merge.neighbours = o.neighbours == "bbox"
                                ? segmentation::NeighbourTest::bounding_box_overlap
                                : segmentation::NeighbourTest::pixel_adjacency;
  params.merge.fit.method = o.fit == "eq6" ? segmentation::PlaneFitMethod::paper_eq6
                                           : segmentation::PlaneFitMethod::total_least_squares;
  params.mode = o.mode == "cells" ? segmentation::PlaneExtractionMode::cells
                                  : segmentation::PlaneExtractionMode::regions;
  return params;
}

io::PlaneRunRecord run_record(const PlanesOptions& o, const compute::Context& context) {
  return {.mode = o.mode,
          .lab_threshold = o.lab_threshold,
          .normal_angle_deg = o.normal_angle_deg,
          .min_plane_pixels = o.min_plane_pixels,
          .neighbours = o.neighbours,
          .fit = o.fit,
          .backend = std::string(compute::to_string(context.backend())),
          .device = context.device_info().name};
}

// An organized PCD: its pixels are the camera's; intrinsics are not needed for the extraction
// (only recorded), so they are estimated as a Kinect's at the cloud's size. Without colour only
// the cells mode takes it.
PlaneInput pcd_input(const fs::path& path, const PlanesOptions& o) {
  const io::PcdCloud cloud = io::read_pcd(path);
  const std::string name = "'" + path.string() + "'";
  require(cloud.organized(), "planes: " + name + " is not organized (height " +
                                 std::to_string(cloud.height) +
                                 "): region growing needs the pixel grid of a depth camera");
  require(!cloud.colors.empty() || o.mode == "cells",
          "planes: " + name +
              " has no colour (rgb/rgba field): the regions mode grows colour regions; "
              "--mode cells works on depth alone");
  PlaneInput input{path.string(), cloud.to_point_image(), RgbImage(), PinholeIntrinsics{}};
  if (!cloud.colors.empty()) {
    input.color = RgbImage(cloud.width, cloud.height);
    std::copy(cloud.colors.begin(), cloud.colors.end(), input.color.data());
  }
  const double f = 525.0 * cloud.width / 640.0;
  input.intrinsics = {
      cloud.width, cloud.height, f, f, (cloud.width - 1) / 2.0, (cloud.height - 1) / 2.0};
  return input;
}

PinholeIntrinsics frame_intrinsics(const PlanesOptions& o, const DepthImage& depth) {
  if (!o.intrinsics.empty()) {
    const PinholeIntrinsics intrinsics = io::read_camera_intrinsics_json(o.intrinsics);
    require(intrinsics.width == depth.width() && intrinsics.height == depth.height(),
            "planes: " + o.intrinsics.string() + " is for " + std::to_string(intrinsics.width) +
                "x" + std::to_string(intrinsics.height) + " images, the depth image is " +
                std::to_string(depth.width()) + "x" + std::to_string(depth.height()));
    return intrinsics;
  }
  const double scale = depth.width() / 640.0;
  const double fx = o.fx > 0 ? o.fx : 525.0 * scale;
  return {depth.width(),
          depth.height(),
          fx,
          o.fy > 0 ? o.fy : fx,  // square pixels unless told otherwise
          o.cx >= 0 ? o.cx : (depth.width() - 1) / 2.0,
          o.cy >= 0 ? o.cy : (depth.height() - 1) / 2.0};
}

PlaneInput rgbd_input(const PlanesOptions& o, const compute::Context& context) {
  require(!o.color.empty() || o.mode == "cells",
          "planes: " + o.input.string() +
              " is a depth image: give its colour image with --color (the regions mode grows "
              "colour regions), or --mode cells for depth alone");
  const DepthImage depth = io::read_depth_png(o.input);
  RgbImage color = o.color.empty() ? RgbImage() : io::read_color_image(o.color);
  require(color.empty() || (color.width() == depth.width() && color.height() == depth.height()),
          "planes: the colour image " + o.color.string() + " is " + std::to_string(color.width()) +
              "x" + std::to_string(color.height()) + ", the depth image " + o.input.string() +
              " is " + std::to_string(depth.width()) + "x" + std::to_string(depth.height()));
  PlaneInput input{o.input.string(), {}, std::move(color), frame_intrinsics(o, depth)};
  input.intrinsics.validate("planes");
  geometry::DepthRange range;
  range.units_per_metre = o.depth_scale > 0 ? o.depth_scale : 1000.0;
  pipeline::check_depth_usable(depth, o.input, range);
  input.points = geometry::backproject(context, depth, input.intrinsics, range);
  return input;
}

// Extracts and writes one frame's files into dir (staging; shown_dir: where they will be); returns
// its summary.
io::PlaneFrameRecord extract_frame(segmentation::PlaneExtractor& extractor, const PlaneInput& input,
                                   const fs::path& dir, const fs::path& shown_dir,
                                   const std::string& run_json, std::ostream& out) {
  const segmentation::PlaneSet set = extractor.extract(input.points, input.color);
  std::size_t valid = 0, labelled = 0;
  for (std::size_t i = 0; i < input.points.size(); ++i) {
    if (!is_valid(input.points.data()[i])) continue;
    ++valid;
    labelled += set.labels.data()[i] != kUnlabeled;
  }
  require(valid > 0, "planes: " + input.name + " has no valid depth");
  {
    const InterruptsDeferred writing;  // a signal waits for the frame's files, then drops them
    fs::create_directories(dir);
    io::write_label_png(dir / "labels.png", set.labels);
    const RgbImage background = input.color.empty() ? io::depth_shading(input.points) : input.color;
    io::write_png(dir / "segmentation.png", io::plane_overlay(background, set.labels));
    io::write_ply(dir / "planes.ply", io::plane_points(input.points, set.labels));
    io::write_planes_json(dir / "planes.json", set, {input.name, input.intrinsics, run_json});
  }
  const double coverage = 100.0 * static_cast<double>(labelled) / static_cast<double>(valid);
  char line[256];
  std::snprintf(line, sizeof(line),
                "planes: %s: %zu planes (%u segments, %u merged), %.1f %% of valid pixels, %.1f ms"
                " -> %s\n",
                input.name.c_str(), set.planes.size(), set.segment_count, set.merged_count,
                coverage, set.timings.total(), shown_dir.string().c_str());
  out << line;
  return {.source = input.name,
          .dir = shown_dir.string(),
          .planes = set.planes.size(),
          .segments = set.segment_count,
          .valid_pixels = valid,
          .plane_pixels = labelled,
          .milliseconds = set.timings.total()};
}

}  // namespace

CLI::App* add_planes_command(CLI::App& app, PlanesOptions& o) {
  CLI::App* command = app.add_subcommand(
      "planes",
      "Planes of an organized PCD, an RGB-D frame (depth PNG + --color; --mode cells: colour "
      "optional) or a sequence folder (docs/methods.md M1: Lab region growing, plane fits, "
      "merging)");
  command
      ->add_option("INPUT", o.input,
                   "Organized PCD, depth PNG, or sequence folder (without colour: --mode cells)")
      ->required();
  command->add_option("--out", o.out_dir, "Output folder")->required();
  command->add_option("--color", o.color,
                      "Colour image of a depth PNG input (the regions mode needs it)");
  command->add_option("--intrinsics", o.intrinsics,
                      "Depth PNG input: camera_intrinsics.json (Open3D format)");
  // Checked when given: 0 and -1 are the defaults' "not given", never a value to fall back from.
  command->add_option("--fx", o.fx, "Depth PNG input: focal length [px] (default 525 at 640 wide)")
      ->check(finite_positive());
  command->add_option("--fy", o.fy, "Depth PNG input: focal length [px] (default: fx)")
      ->check(finite_positive());
  command->add_option("--cx", o.cx, "Depth PNG input: principal point [px] (default: centre)")
      ->check(finite_in(0, 1e6));
  command->add_option("--cy", o.cy, "Depth PNG input: principal point [px]")
      ->check(finite_in(0, 1e6));
  command
      ->add_option("--depth-scale", o.depth_scale,
                   "Units per metre (default: 1000 for a depth PNG, the layout's for a sequence)")
      ->check(finite_positive())
      ->capture_default_str();
  command->add_option("--first", o.first, "Sequence: first frame")
      ->check(whole_number(kMaxFrames))
      ->capture_default_str();
  command->add_option("--frames", o.frames, "Sequence: number of frames (0: to the end)")
      ->check(whole_number(kMaxFrames))
      ->capture_default_str();
  add_sequence_input_options(*command, o.sequence, false, false);
  command->add_option("--step", o.step, "Sequence: every step-th frame")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  command->add_option("--lab-threshold", o.lab_threshold, "Region growing: Lab distance")
      ->check(finite_in(0.1, 1000.0))
      ->capture_default_str();
  command->add_option("--normal-angle", o.normal_angle_deg, "Merging: max normal angle [deg]")
      ->check(finite_in(0.0, 180.0))
      ->capture_default_str();
  command->add_option("--min-plane-pixels", o.min_plane_pixels, "Smallest plane kept [pixels]")
      ->check(whole_number(1000000000))
      ->capture_default_str();
  command->add_option("--neighbours", o.neighbours, "Merging neighbours: pixel | bbox (the paper)")
      ->check(CLI::IsMember({"pixel", "bbox"}))
      ->capture_default_str();
  command->add_option("--fit", o.fit, "Plane fit: tls | eq6 (the paper's z = Ax + By + C)")
      ->check(CLI::IsMember({"tls", "eq6"}))
      ->capture_default_str();
  add_backend_option(*command, o.backend, o.backend_source);
  command
      ->add_option("--mode", o.mode,
                   "regions (the M1 paper's Lab region growing) | cells (planar cells first, "
                   "colour only to join planes apart; docs/planes.md)")
      ->check(CLI::IsMember({"regions", "cells"}))
      ->capture_default_str();
  command->add_flag("--force", o.force, "Replace the folder of an earlier run as a whole");
  command->add_flag("!--no-progress", o.progress, "No progress bar on stderr (sequences)");
  return command;
}

int run_planes_command(const PlanesOptions& o, std::ostream& out, std::ostream& err) {
  require(fs::exists(o.input), "planes: " + o.input.string() + ": no such file or folder");
  const compute::Context context = backend_context(o.backend, o.backend_source);
  const segmentation::PlaneExtractionParams params = extraction_params(o);
  params.validate();
  const io::PlaneRunRecord run = run_record(o, context);
  const std::string run_json = io::plane_run_json(run);
  OutputFolder folder(
      "planes", o.out_dir, o.force,
      {"planes.json", "labels.png", "segmentation.png", "planes.ply", "summary.json"});

  if (!fs::is_directory(o.input)) {
    std::string extension = o.input.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const PlaneInput input = extension == ".pcd" ? pcd_input(o.input, o) : rgbd_input(o, context);
    segmentation::PlaneExtractor extractor(context, input.intrinsics, params);
    extract_frame(extractor, input, folder.dir(), o.out_dir, run_json, out);
    folder.commit();
    return 0;
  }

  SequenceInputOptions reading = o.sequence;
  reading.depth_scale = o.depth_scale;
  reading.first = o.first;
  reading.frames = o.frames;
  reading.step = o.step;
  const io::OpenedSequence opened = open_input(o.input, reading, err);
  if (o.mode != "cells") {
    require_colour(opened, o.input,
                   "the regions mode (Lab region growing; --mode cells works on depth alone)");
  }
  const io::Sequence& sequence = *opened.sequence;
  segmentation::PlaneExtractor extractor(context, sequence.intrinsics(), params);
  geometry::DepthRange range;
  range.units_per_metre = sequence.depth_units_per_metre();
  ProgressBar bar(err, o.progress);
  std::vector<io::PlaneFrameRecord> frames;
  const std::size_t total = sequence.size();
  for (std::size_t i = 0; i < total; ++i) {
    io::RgbdFrame frame = sequence.frame(i);
    char number[32];
    std::snprintf(number, sizeof(number), "%06zu", frame.index);
    PlaneInput input{o.input.string() + " frame " + std::to_string(frame.index),
                     geometry::backproject(context, frame.depth, sequence.intrinsics(), range),
                     std::move(frame.color), sequence.intrinsics()};
    frames.push_back(
        extract_frame(extractor, input, folder.dir() / number, o.out_dir / number, run_json, out));
    bar.update("planes", frames.size(), total);
  }
  bar.finish();
  io::write_text_file(folder.dir() / "summary.json",
                      io::plane_sequence_summary_json(o.input.string(), opened, run, frames));
  folder.commit();
  return 0;
}

}  // namespace kartograf::cli
