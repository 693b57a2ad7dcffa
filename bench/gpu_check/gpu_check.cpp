// kartograf_gpu_check: lists the compute devices, then times every device operation and the
// per-frame odometry on each backend beside the CPU path, on real 7-Scenes frames (640x480 and
// enlarged to 1280x720) and random depth; prints one table last and writes gpu-check.json. Needs
// only the compute core (no OpenCV): scripts/gpu-check.sh carries it to a GPU machine.
//   kartograf_gpu_check --data DIR [--out DIR] [--quick] [--backends cpu,vulkan,opencl] [--frames
//   N] kartograf_gpu_check --list   (the devices, then "available: cpu,vulkan,..." on the last
//   line)
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "backend_run.hpp"
#include "kartograf/compute/backend.hpp"
#include "kartograf/core/error.hpp"
#include "results.hpp"

namespace kartograf::gpu_check {
namespace {

struct Arguments {
  std::filesystem::path data, out = ".";
  bool quick = false;
  bool list_only = false;
  std::vector<std::string> backends = {"cpu", "vulkan", "opencl"};
  int frames = 30;
};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    if (comma > start) parts.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return parts;
}

Arguments parse(int argc, char** argv) {
  Arguments args;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    const auto value = [&]() -> std::string {
      require(i + 1 < argc, "kartograf_gpu_check: " + flag + " needs a value");
      return argv[++i];
    };
    if (flag == "--data") {
      args.data = value();
    } else if (flag == "--out") {
      args.out = value();
    } else if (flag == "--list") {
      args.list_only = true;
    } else if (flag == "--quick") {
      args.quick = true;
    } else if (flag == "--backends") {
      args.backends = split(value());
    } else if (flag == "--frames") {
      args.frames = std::stoi(value());
    } else {
      throw Error("kartograf_gpu_check: unknown option '" + flag +
                  "' (--data DIR --out DIR --quick --backends LIST --frames N --list)");
    }
  }
  if (args.list_only) return args;
  require(!args.data.empty(),
          "kartograf_gpu_check: --data DIR (the exported device data) is required");
  require(args.frames >= 2, "kartograf_gpu_check: --frames must be at least 2");
  return args;
}

void list_devices(std::ostream& out) {
  out << "== devices\n";
  std::string available;
  for (const compute::BackendStatus& backend : compute::probe_backends()) {
    if (backend.available) {
      if (!available.empty()) available += ',';
      available += compute::to_string(backend.backend);
    }
    out << compute::to_string(backend.backend) << ": "
        << (backend.available ? "available" : "unavailable: " + backend.reason) << "\n";
    for (const compute::DeviceInfo& device : backend.devices) {
      out << "  " << device.name << " [" << compute::to_string(device.type) << "] "
          << device.api_version << "; driver " << device.driver << "; "
          << device.memory_bytes / (1024 * 1024) << " MiB"
          << (device.usable ? "" : "; NOT USABLE: " + device.unusable_reason) << "\n"
          << "    " << compute::describe(device.limits) << "\n";
    }
  }
  out << "available: " << available << "\n";
}

int run(const Arguments& args) {
  list_devices(std::cout);
  if (args.list_only) return 0;
  Inputs inputs = load_inputs(args.data, args.quick ? 6 : args.frames);
  const Repetitions repetitions = args.quick ? Repetitions{1, 3} : Repetitions{5, 30};
  Results results;
  SequenceReference reference;  // the CPU backend's poses, computed first
  bool failed = false;
  for (const std::string& name : args.backends) {
    const compute::BackendKind kind = to_backend_kind(name);
    failed |= !run_backend(kind, inputs, repetitions, reference, results, std::cout);
  }
  print_table(std::cout, results);
  std::filesystem::create_directories(args.out);
  std::ofstream table(args.out / "gpu-check-table.txt");
  print_table(table, results);
  write_json(args.out / "gpu-check.json", results);
  std::cout << "wrote " << (args.out / "gpu-check.json").string() << "\n";
  return failed ? 1 : 0;
}

}  // namespace
}  // namespace kartograf::gpu_check

int main(int argc, char** argv) {
  try {
    return kartograf::gpu_check::run(kartograf::gpu_check::parse(argc, argv));
  } catch (const std::exception& error) {
    std::cerr << "kartograf_gpu_check: " << error.what() << "\n";
    return 2;
  }
}
