#pragma once
// What the check measured, printed as one table and written as JSON.
#include <filesystem>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace kartograf::gpu_check {

struct OperationResult {
  std::string backend, input, operation;
  int width = 0, height = 0;
  double wall_ms = 0;    // median per call, dispatch to finish
  double device_ms = 0;  // median per call of the device's timestamps; 0: not timed
  double bytes_per_pixel = 0;
  std::map<std::string, double> command_ms;  // median per call, per command
};

struct SequenceResult {
  std::string backend, input;
  int frames = 0;
  double wall_ms_per_frame = 0, device_ms_per_frame = 0;
  double max_translation_difference_m = -1;  // against the CPU backend's poses; -1: not compared
  double max_rotation_difference_deg = -1;
  std::map<std::string, double> command_ms_per_frame;  // device time per command, mean per frame
};

struct BackendResult {
  std::string backend, device, driver, limits;
  std::string error;         // why it stopped (an Error from the backend); empty: ran
  double copy_gb_per_s = 0;  // device-to-device copy, bytes read + written per second
  double copy_buffer_mib = 0;
};

struct Results {
  std::vector<BackendResult> backends;
  std::vector<OperationResult> operations;
  std::vector<SequenceResult> sequences;
  std::vector<std::string> notes;
};

// Rows: operation and input; columns per backend: wall ms, device ms, and for the device backends
// the device time over the bandwidth floor (bytes / measured copy bandwidth).
void print_table(std::ostream& out, const Results& results);
void write_json(const std::filesystem::path& path, const Results& results);

}  // namespace kartograf::gpu_check
