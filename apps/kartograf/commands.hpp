#pragma once
// The CLI's subcommands. Each returns the process exit code and throws kartograf::Error on
// failure (main reports it).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "kartograf/compute/backend.hpp"
#include "kartograf/core/intrinsics.hpp"

namespace CLI {
class App;
}  // namespace CLI

namespace kartograf::cli {

// Every backend and its devices in detail.
int run_devices_command(std::ostream& out);

// One line per backend: available with its devices, or why not.
void print_backend_summary(std::ostream& out, const std::vector<compute::BackendStatus>& backends);

struct DemoOptions {
  std::filesystem::path out_dir = "kartograf-demo";
  std::string backend = "auto";
  std::string backend_source = "--backend";  // names the setting in errors
};

// Renders a depth frame of the default synthetic world (synth/), back-projects it, estimates
// normals and writes pictures and a cloud.
int run_demo_command(const DemoOptions& options, std::ostream& out);

// `eval traj|planes|rooms|semantic GT PREDICTION`: add_eval_command registers the subcommands
// (parsing fills options); run_eval_command prints the chosen metric's table or JSON object.
struct EvalOptions {
  std::string metric;  // the subcommand given
  std::filesystem::path ground_truth, prediction;
  bool json = false;
  double delta = 1;                   // traj
  std::string delta_unit = "frames";  // traj
  bool sim3 = false;                  // traj
  double max_difference = 0.02;       // traj
  double threshold = 0.8;             // planes
};
CLI::App* add_eval_command(CLI::App& app, EvalOptions& options);
int run_eval_command(const EvalOptions& options, std::ostream& out);

// `synth --out DIR ...`: a synthetic RGB-D data set with exact ground truth; progress on err.
struct SynthOptions {
  std::filesystem::path out_dir;
  std::uint64_t seed = 1;
  int frames = 300;
  std::string trajectory = "robot";  // robot | handheld
  int room = 0;                      // handheld: room id, 0 = the largest
  PinholeIntrinsics intrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};
  bool no_noise = false;
  bool force = false;
  int threads = 0;
};
CLI::App* add_synth_command(CLI::App& app, SynthOptions& options);
int run_synth_command(const SynthOptions& options, std::ostream& out, std::ostream& err);

}  // namespace kartograf::cli
