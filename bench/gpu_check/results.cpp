#include "results.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "kartograf/core/error.hpp"

namespace kartograf::gpu_check {

namespace {

std::string fixed(double value, int decimals = 3) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

// The card's copy bandwidth: the fastest device-to-device copy any device backend measured
// (Vulkan's vkCmdCopyBuffer and OpenCL's clEnqueueCopyBuffer differ by 3.5x on an H100).
double floor_gb_per_s(const Results& results) {
  double best = 0;
  for (const BackendResult& backend : results.backends) {
    if (backend.backend != "cpu") best = std::max(best, backend.copy_gb_per_s);
  }
  return best;
}

// "0.123 / 0.100 (1.4x)": wall / device (device time over the bandwidth floor), or "-".
std::string cell(const Results& results, const OperationResult* row) {
  if (!row) return "-";
  std::string text = fixed(row->wall_ms);
  if (row->device_ms <= 0) return text;
  text += " / " + fixed(row->device_ms);
  const double bandwidth = floor_gb_per_s(results);
  if (row->bytes_per_pixel > 0 && bandwidth > 0) {
    const double floor_ms = row->bytes_per_pixel * row->width * row->height / (bandwidth * 1e6);
    text += " (" + fixed(row->device_ms / floor_ms, 1) + "x)";
  }
  return text;
}

// The commands that take most of a sequence's device time, largest first: where one backend spends
// more than another shows here.
void print_top_commands(std::ostream& out, const std::map<std::string, double>& command_ms) {
  std::vector<std::pair<double, std::string>> ranked;
  for (const auto& [command, ms] : command_ms) ranked.emplace_back(ms, command);
  std::sort(ranked.rbegin(), ranked.rend());
  if (ranked.size() > 8) ranked.resize(8);
  if (ranked.empty()) return;
  out << "    device ms/frame by command:";
  for (const auto& [ms, command] : ranked) out << " " << command << " " << fixed(ms, 3);
  out << "\n";
}

}  // namespace

void print_table(std::ostream& out, const Results& results) {
  std::vector<std::string> names;
  for (const BackendResult& backend : results.backends) names.push_back(backend.backend);
  out << "\n== kartograf gpu-check: median ms per call, wall / device (device over the "
         "bandwidth floor)\n";
  for (const BackendResult& b : results.backends) {
    out << "  " << b.backend << ": " << (b.error.empty() ? b.device : "FAILED: " + b.error);
    if (b.copy_gb_per_s > 0) out << "; copy " << fixed(b.copy_gb_per_s, 1) << " GB/s";
    out << "\n";
  }
  out << "  bandwidth floor: " << fixed(floor_gb_per_s(results), 1)
      << " GB/s (the fastest device copy above; bytes read + written)\n";
  char line[512];
  std::snprintf(line, sizeof(line), "%-34s %-17s", "operation", "input");
  out << line;
  for (const std::string& name : names) {
    std::snprintf(line, sizeof(line), " | %-28s", name.c_str());
    out << line;
  }
  out << "\n";
  std::vector<std::pair<std::string, std::string>> keys;  // (operation, input) in first-seen order
  for (const OperationResult& r : results.operations) {
    const std::pair<std::string, std::string> key{r.operation, r.input};
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
  }
  for (const auto& [operation, input] : keys) {
    std::snprintf(line, sizeof(line), "%-34s %-17s", operation.c_str(), input.c_str());
    out << line;
    for (const std::string& name : names) {
      const OperationResult* found = nullptr;
      for (const OperationResult& r : results.operations) {
        if (r.operation == operation && r.input == input && r.backend == name) found = &r;
      }
      std::snprintf(line, sizeof(line), " | %-28s", cell(results, found).c_str());
      out << line;
    }
    out << "\n";
  }
  for (const SequenceResult& s : results.sequences) {
    out << "odometry sequence " << s.input << " " << s.backend << ": " << s.frames << " frames, "
        << fixed(s.wall_ms_per_frame) << " ms/frame wall ("
        << fixed(s.wall_ms_per_frame > 0 ? 1000.0 / s.wall_ms_per_frame : 0, 0) << " frames/s), "
        << fixed(s.device_ms_per_frame) << " ms/frame device";
    if (s.max_translation_difference_m >= 0) {
      out << "; vs cpu: max " << fixed(1000 * s.max_translation_difference_m, 3) << " mm, "
          << fixed(s.max_rotation_difference_deg, 4) << " deg";
    }
    out << "\n";
    print_top_commands(out, s.command_ms_per_frame);
  }
  for (const std::string& note : results.notes) out << "note: " << note << "\n";
}

void write_json(const std::filesystem::path& path, const Results& results) {
  nlohmann::json json;
  for (const BackendResult& b : results.backends) {
    json["backends"].push_back({{"backend", b.backend},
                                {"device", b.device},
                                {"driver", b.driver},
                                {"limits", b.limits},
                                {"error", b.error},
                                {"copy_gb_per_s", b.copy_gb_per_s},
                                {"copy_buffer_mib", b.copy_buffer_mib}});
  }
  for (const OperationResult& r : results.operations) {
    json["operations"].push_back({{"backend", r.backend},
                                  {"input", r.input},
                                  {"operation", r.operation},
                                  {"width", r.width},
                                  {"height", r.height},
                                  {"wall_ms", r.wall_ms},
                                  {"device_ms", r.device_ms},
                                  {"bytes_per_pixel", r.bytes_per_pixel},
                                  {"command_ms", r.command_ms}});
  }
  for (const SequenceResult& s : results.sequences) {
    json["sequences"].push_back({{"backend", s.backend},
                                 {"input", s.input},
                                 {"frames", s.frames},
                                 {"wall_ms_per_frame", s.wall_ms_per_frame},
                                 {"device_ms_per_frame", s.device_ms_per_frame},
                                 {"max_translation_difference_m", s.max_translation_difference_m},
                                 {"max_rotation_difference_deg", s.max_rotation_difference_deg},
                                 {"command_ms_per_frame", s.command_ms_per_frame}});
  }
  json["notes"] = results.notes;
  std::ofstream out(path);
  out << json.dump(2) << "\n";
  require(static_cast<bool>(out), "gpu-check: cannot write " + path.string());
}

}  // namespace kartograf::gpu_check
