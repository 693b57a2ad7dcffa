// `kartograf rooms MAP --method NAME --out DIR`: room segmentation of a 2-D occupancy map (an
// ipa-style PNG or a ROS map YAML): DIR/rooms.png (16-bit room id per cell, 0 = no room),
// DIR/rooms_color.png (for people) and DIR/rooms.json (rooms, areas, neighbours, doorways).
// `kartograf rooms-eval FOLDER`: every method on every map of a benchmark folder against its
// NAME_gt_segmentation.png; a table per method and map variant, and a CSV row per map.
// Wiring only: the methods live in rooms/, the metrics in eval/.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "backend_option.hpp"
#include "commands.hpp"
#include "interrupts.hpp"
#include "kartograf/compute/context.hpp"
#include "kartograf/core/error.hpp"
#include "kartograf/eval/room_metrics.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/formats/occupancy_map_io.hpp"
#include "kartograf/formats/text_file.hpp"
#include "kartograf/outputs/room_io.hpp"
#include "kartograf/outputs/room_run.hpp"
#include "kartograf/rooms/room_methods.hpp"
#include "option_checks.hpp"
#include "output_transaction.hpp"
#include "sequence_run.hpp"

namespace kartograf::cli {

namespace {

namespace fs = std::filesystem;

std::string method_names() {
  std::string names;
  for (const rooms::RoomMethod m : rooms::all_room_methods()) {
    if (!names.empty()) names += '|';
    names += rooms::to_string(m);
  }
  return names;
}

// A ROS map (YAML with its image) or an ipa-style PNG read at `resolution`.
OccupancyGrid read_map(const fs::path& path, double resolution, int free_threshold,
                       bool resolution_given) {
  require(fs::exists(path), "rooms: " + path.string() + ": no such file");
  require(std::isfinite(resolution) && resolution > 0,
          "rooms: --resolution must be > 0 m/cell, got " + std::to_string(resolution));
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".yaml" || extension == ".yml") {
    OccupancyGrid map = io::read_ros_map(path);
    if (resolution_given) map.resolution = resolution;
    return map;
  }
  return io::read_png_map(path, resolution, free_threshold);
}

rooms::RoomMethodParams method_options(const RoomsOptions& o) {
  rooms::RoomMethodParams options;
  if (o.min_area_m2 >= 0 || o.max_area_m2 >= 0) {
    require(o.min_area_m2 >= 0 && o.max_area_m2 > o.min_area_m2,
            "rooms: --min-area and --max-area go together, with 0 <= min < max");
    options.room_area = rooms::AreaLimits{o.min_area_m2, o.max_area_m2};
  }
  if (o.keep_furniture) options.furniture.reset();
  options.model = o.model;
  return options;
}

// The backend of the feature method's laser scans, made only when that method runs.
// The backend the feature method's laser scans run on; the other methods run on the host, so they
// take the CPU context and never open a device.
compute::Context scan_context(const RoomsOptions& o, bool needed) {
  if (!needed) return compute::Context::cpu();
  return backend_context(o.backend, o.backend_source);
}

void add_map_options(CLI::App* command, RoomsOptions& o) {
  command->add_option("--resolution", o.resolution, "PNG maps: metres per cell")
      ->check(finite_positive())
      ->capture_default_str();
  command->add_option("--free-threshold", o.free_threshold, "PNG maps: grey >= this is free space")
      ->check(CLI::Range(1, 255))
      ->capture_default_str();
  // Checked when given: the negative defaults mean "the method's", never a value to fall back from.
  command->add_option("--min-area", o.min_area_m2, "Smallest room [m^2] (default: the method's)")
      ->check(finite_in(0, 1e12));
  command->add_option("--max-area", o.max_area_m2, "Largest room [m^2] (default: the method's)")
      ->check(finite_in(0, 1e12));
  add_backend_option(*command, o.backend, o.backend_source, "feature: where the laser scans run, ");
  command->add_flag("--keep-furniture", o.keep_furniture,
                    "Segment the map as it is, furniture included (the reference's behaviour)");
  command->add_option("--model", o.model,
                      "feature, vrf: the trained model (default: the shipped one)");
}

// Mean and total recall/precision over a group of maps, as the survey reports them.
struct GroupScores {
  int maps = 0;
  double recall_mean = 0, precision_mean = 0, recall_total = 0, precision_total = 0, mcc = 0;
  std::vector<double> seconds;
  void add(const eval::RoomSegmentationScores& s, double time) {
    ++maps;
    recall_mean += s.recall_mean;
    precision_mean += s.precision_mean;
    recall_total += s.recall_total;
    precision_total += s.precision_total;
    mcc += s.mcc;
    seconds.push_back(time);
  }
};

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::string percent(double sum, int n) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", n ? 100.0 * sum / n : 0.0);
  return text;
}

std::string fixed(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

}  // namespace

CLI::App* add_rooms_command(CLI::App& app, RoomsOptions& o) {
  CLI::App* command = app.add_subcommand(
      "rooms", "Room segmentation of a 2-D occupancy map (PNG or ROS YAML; docs/methods.md M4)");
  command->add_option("MAP", o.map, "Map: ipa-style PNG (free = white) or ROS map YAML")
      ->required();
  command->add_option("--out", o.out_dir, "Output folder")->required();
  command->add_option("--method", o.method, method_names())->capture_default_str();
  add_map_options(command, o);
  command->add_flag("--force", o.force, "Replace the folder of an earlier run as a whole");
  return command;
}

int run_rooms_command(const RoomsOptions& o, bool resolution_given, std::ostream& out) {
  const rooms::RoomMethod method = rooms::parse_room_method(o.method);
  rooms::RoomMethodParams options = method_options(o);
  const compute::Context context = scan_context(o, method == rooms::RoomMethod::feature);
  const OccupancyGrid map = read_map(o.map, o.resolution, o.free_threshold, resolution_given);
  OutputFolder folder("rooms", o.out_dir, o.force, {"rooms.png", "rooms_color.png", "rooms.json"});
  const rooms::RoomSegmentation result = rooms::segment_rooms(context, map, method, options);
  const InterruptsDeferred writing;  // a signal waits for the files, then drops them
  const fs::path& dir = folder.dir();
  // Everything is computed before the first file is written; each write is atomic.
  const std::string run_json = io::room_run_json({o.method, map.resolution, o.free_threshold});
  io::write_label_png(dir / "rooms.png", result.rooms);
  io::write_png(dir / "rooms_color.png", io::room_overlay(map, result.rooms));
  io::write_rooms_json(dir / "rooms.json", result, map, o.map.string(), run_json);
  folder.commit();
  double area = 0;
  for (const rooms::RoomRecord& r : result.records) area += r.area_m2;
  out << o.map.string() << ": " << result.records.size() << " rooms, " << fixed(area, 1) << " m^2, "
      << o.method << " in " << fixed(result.seconds, 3) << " s -> " << o.out_dir.string() << "\n";
  return 0;
}

CLI::App* add_rooms_eval_command(CLI::App& app, RoomsEvalOptions& o) {
  CLI::App* command = app.add_subcommand(
      "rooms-eval",
      "Every room segmentation method on a folder of maps with NAME_gt_segmentation.png "
      "(recall/precision as ipa_room_segmentation reports them, MCC)");
  command->add_option("FOLDER", o.folder, "Folder of maps, e.g. ipa_room_maps/test_maps")
      ->required();
  command->add_option("--methods", o.methods, "Methods to run (default: all): " + method_names())
      ->delimiter(',');
  command->add_option("--csv", o.csv, "Write one row per method and map here");
  command->add_flag("--force", o.force, "Replace an existing --csv file");
  command->add_option("--only", o.only, "Only maps whose name contains this");
  add_map_options(command, o.map);
  command->add_flag("!--no-progress", o.progress, "No progress on stderr");
  return command;
}

int run_rooms_eval_command(const RoomsEvalOptions& o, std::ostream& out, std::ostream& err) {
  OutputFiles files("rooms-eval", o.force);
  const fs::path csv_file = o.csv.empty() ? o.csv : files.add("--csv", o.csv);
  std::vector<rooms::RoomMethod> methods;
  for (const std::string& name : o.methods) methods.push_back(rooms::parse_room_method(name));
  if (methods.empty()) methods = rooms::all_room_methods();
  rooms::RoomMethodParams options = method_options(o.map);
  const compute::Context context =
      scan_context(o.map, std::find(methods.begin(), methods.end(), rooms::RoomMethod::feature) !=
                              methods.end());
  std::vector<io::RoomMapCase> cases = io::find_room_maps(o.folder);
  if (!o.only.empty()) {
    std::erase_if(
        cases, [&](const io::RoomMapCase& c) { return c.name.find(o.only) == std::string::npos; });
    require(!cases.empty(),
            "rooms-eval: no map name in " + o.folder.string() + " contains '" + o.only + "'");
  }

  std::ostringstream csv;
  csv << "method,map,variant,rooms,segments,recall_mean,precision_mean,recall_total,"
         "precision_total,mcc,seconds\n";
  std::map<std::string, LabelImage> truths;
  ProgressBar bar(err, o.progress);
  std::size_t done = 0;
  for (const rooms::RoomMethod method : methods) {
    std::map<std::string, GroupScores> groups;
    for (const io::RoomMapCase& c : cases) {
      auto truth = truths.find(c.name);
      if (truth == truths.end())
        truth = truths.emplace(c.name, io::read_room_ground_truth_png(c.ground_truth)).first;
      const OccupancyGrid map = io::read_png_map(c.map, o.map.resolution, o.map.free_threshold);
      const rooms::RoomSegmentation result = rooms::segment_rooms(context, map, method, options);
      const eval::RoomSegmentationScores s = eval::evaluate_room_segmentation(
          truth->second, result.rooms, eval::room_evaluation_params(map.resolution));
      groups[c.variant].add(s, result.seconds);
      csv << rooms::to_string(method) << ',' << c.name << ',' << c.variant << ','
          << s.ground_truth_rooms << ',' << s.segments << ',' << fixed(s.recall_mean, 4) << ','
          << fixed(s.precision_mean, 4) << ',' << fixed(s.recall_total, 4) << ','
          << fixed(s.precision_total, 4) << ',' << fixed(s.mcc, 4) << ','
          << fixed(result.seconds, 4) << "\n";
      bar.update("rooms-eval " + rooms::to_string(method), ++done, cases.size() * methods.size());
    }
    bar.finish();
    out << "\n"
        << rooms::to_string(method) << " (" << o.folder.string() << ")\n\n"
        << "| variant | maps | recall % (mean) | precision % (mean) | recall % (area) | "
           "precision % (area) | MCC | median s | max s |\n"
        << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const std::string& variant : io::room_map_variants()) {
      const auto g = groups.find(variant);
      if (g == groups.end()) continue;
      const GroupScores& s = g->second;
      out << "| " << variant << " | " << s.maps << " | " << percent(s.recall_mean, s.maps) << " | "
          << percent(s.precision_mean, s.maps) << " | " << percent(s.recall_total, s.maps) << " | "
          << percent(s.precision_total, s.maps) << " | " << fixed(s.maps ? s.mcc / s.maps : 0, 3)
          << " | " << fixed(median(s.seconds), 3) << " | "
          << fixed(*std::max_element(s.seconds.begin(), s.seconds.end()), 3) << " |\n";
    }
    out.flush();
  }
  if (!o.csv.empty()) {
    const InterruptsDeferred writing;  // a signal waits for the file, then drops it
    io::write_text_file(csv_file, csv.str());
    files.commit();
  }
  return 0;
}

}  // namespace kartograf::cli
