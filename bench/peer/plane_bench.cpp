// The plane part of kartograf_peer_bench.
//
//   frames   synthetic robot-tour frames with exact plane ids, 7-Scenes RedKitchen frames, the 6
//            organized mOSD frames; all 640x480. Every method gets the same organized cloud and
//            colour per frame (plane_data.hpp), converted to its library's types outside the
//            timing.
//   timing   per method: one untimed warm-up call on the first frame, then per frame calls until
//            --min-time seconds have passed (1 to --max-calls); the frame's time is their median,
//            the method's the median over all frames. Wall clock and process CPU time.
//   quality  every method's planes become a plane id per pixel (plane_methods.hpp) and are
//            scored by the same rules (plane_report.hpp).
#include "plane_bench.hpp"

#include <cctype>
#include <iostream>
#include <map>
#include <ostream>

#include "kartograf/core/error.hpp"
#include "kartograf/formats/image_io.hpp"
#include "kartograf/outputs/plane_io.hpp"
#include "peer_report.hpp"
#include "plane_methods.hpp"
#include "plane_report.hpp"

namespace kartograf::peer {
namespace {

std::vector<PlaneFrame> load_frames(const PlaneBenchOptions& options) {
  std::vector<PlaneFrame> frames;
  const auto append = [&frames](std::vector<PlaneFrame> more) {
    for (PlaneFrame& frame : more) frames.push_back(std::move(frame));
  };
  if (options.synthetic_frames > 0) append(synthetic_plane_frames(options.synthetic_frames));
  if (!options.seven_scenes.empty()) {
    const Dataset dataset = open_seven_scenes_dataset(options.seven_scenes);
    append(seven_scenes_plane_frames(dataset, options.seven_scenes_frames));
  }
  if (!options.mosd.empty()) append(mosd_plane_frames(options.mosd));
  require(!frames.empty(), "plane part: no frames (synthetic, 7-Scenes and mOSD all skipped)");
  return frames;
}

std::vector<PlaneMethod> all_methods(const PlaneBenchOptions& options) {
  std::vector<PlaneMethod> methods;
  for (auto&& list : {kartograf_plane_methods(options.device_backends), options.peers}) {
    for (const PlaneMethod& method : list) {
      // Kartograf's CPU row stays: every ratio refers to it.
      if (options.only.empty() || method.name.find(options.only) != std::string::npos ||
          method.name == kKartografPlanes) {
        methods.push_back(method);
      }
    }
  }
  return methods;
}

// "pcl OrganizedMultiPlaneSegmentation + refine" -> "pcl_organizedmultiplanesegmentation_refine"
std::string file_name(const std::string& text) {
  std::string name;
  for (const char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      name += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!name.empty() && name.back() != '_') {
      name += '_';
    }
  }
  while (!name.empty() && name.back() == '_') name.pop_back();
  return name;
}

// Each named part's median over the calls of one frame (every call reports the same names).
TimeParts median_parts(const std::vector<TimeParts>& calls) {
  TimeParts parts = calls.front();
  for (std::size_t p = 0; p < parts.size(); ++p) {
    std::vector<double> values;
    for (const TimeParts& call : calls) values.push_back(call[p].second);
    parts[p].second = median(std::move(values));
  }
  return parts;
}

PlaneMethodOutcome run_method(const PlaneMethod& method, const std::vector<PlaneFrame>& frames,
                              const PlaneBenchOptions& options) {
  std::cerr << "  " << method.name << std::flush;
  PlaneMethodOutcome outcome{&method, {}};
  method.prepare(frames.front()).call();  // warm-up: lazy initialisation, first allocations
  for (const PlaneFrame& frame : frames) {
    const PlaneRun run = method.prepare(frame);
    CallTimes times;
    const std::vector<TimeParts> parts = time_calls(run.call, options.timing, times);
    const PlaneOutput output = run.output();
    outcome.frames.push_back({&frame, median(times.seconds), median(times.cpu_seconds),
                              median_parts(parts), score_planes(frame, output),
                              labels_hash(output.labels)});
    if (!options.overlays.empty()) {
      const std::filesystem::path folder = options.overlays / file_name(method.name);
      std::filesystem::create_directories(folder);
      io::write_png(folder / (file_name(frame.name) + ".png"),
                    io::plane_overlay(frame.color, output.labels));
    }
  }
  std::vector<double> seconds;
  for (const PlaneFrameOutcome& frame : outcome.frames) seconds.push_back(frame.seconds);
  std::cerr << ": " << fixed(1000 * median(seconds), 1) << " ms\n";
  return outcome;
}

void describe_frames(std::ostream& out, const std::vector<PlaneFrame>& frames) {
  std::map<PlaneDataset, std::vector<std::string>> names;
  std::vector<double> truth_planes, large_planes;
  for (const PlaneFrame& frame : frames) {
    names[frame.dataset].push_back(frame.name.substr(frame.name.find(' ') + 1));
    if (frame.dataset != PlaneDataset::synthetic) continue;
    // The ground truth scored as a method: its own planes, all detected.
    const PlaneScore truth = score_planes(frame, {frame.truth, frame.truth_normals});
    truth_planes.push_back(truth.planes);
    large_planes.push_back(truth.large_truth);
  }
  out << frames.size() << " frames, 640x480:";
  for (const auto& [dataset, list] : names) {
    out << " " << to_string(dataset) << " (" << list.size() << ":";
    for (const std::string& name : list) out << " " << name;
    out << ")";
  }
  out << ".";
  if (!truth_planes.empty()) {
    out << " Synthetic ground truth: median " << fixed(median(truth_planes), 1)
        << " planes per frame, " << fixed(median(large_planes), 1) << " over 1 % of the image.";
  }
  out << "\n\n";
}

}  // namespace

void run_plane_bench(const PlaneBenchOptions& options, std::ostream& out) {
  std::cerr << "plane part: loading frames\n";
  const std::vector<PlaneFrame> frames = load_frames(options);
  const std::vector<PlaneMethod> methods = all_methods(options);
  out << "\n# Plane segmentation\n\n"
      << "- timing: per frame the median of 1-" << options.timing.max_calls << " calls (until "
      << options.timing.min_time
      << " s have passed) after one warm-up call on the first frame, per method the median over "
         "all frames; wall clock and process CPU time (all threads); ratio = method time / "
         "Kartograf CPU time\n- frames: ";
  describe_frames(out, frames);
  std::vector<PlaneMethodOutcome> outcomes;
  for (const PlaneMethod& method : methods) outcomes.push_back(run_method(method, frames, options));
  print_plane_table(out, outcomes);
  print_kartograf_stage_line(out, outcomes);
  out << "\nPer data set (median over its frames):\n\n";
  print_plane_dataset_table(out, outcomes);
  out << "\nSettings:\n\n";
  for (const PlaneMethod& method : methods)
    out << "- " << method.name << ": " << method.settings << "\n";
  print_plane_throughput(out, methods, frames, options.throughput);
  if (options.details) print_plane_details(std::cerr, outcomes);
  out.flush();
}

}  // namespace kartograf::peer
