#include "bench_support.hpp"

#include <cstdlib>
#include <iostream>
#include <sstream>

namespace kartograf::bench {

namespace {

bool listed(compute::BackendKind kind) {
  const char* names = std::getenv("KARTOGRAF_BENCH_BACKENDS");
  if (!names || !*names) return true;
  std::stringstream stream(names);
  std::string name;
  while (std::getline(stream, name, ',')) {
    if (name == compute::to_string(kind)) return true;
  }
  return false;
}

}  // namespace

std::vector<compute::BackendKind> backends_to_run() {
  std::vector<compute::BackendKind> kinds;
  for (const compute::BackendStatus& status : compute::probe_backends()) {
    if (!listed(status.backend)) continue;
    if (!status.available) {
      std::cerr << "skipping " << compute::to_string(status.backend) << ": " << status.reason
                << "\n";
      continue;
    }
    kinds.push_back(status.backend);
  }
  return kinds;
}

compute::ContextParams context_options(compute::BackendKind backend) {
  compute::ContextParams options;
  options.backend = compute::choice_of(backend);
  return options;
}

std::string case_name(const std::string& operation, compute::BackendKind backend,
                      const std::string& size) {
  return operation + "/" + std::string(compute::to_string(backend)) + "/" + size;
}

benchmark::internal::Benchmark* repeated(benchmark::internal::Benchmark* bench, int repetitions) {
  return bench->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Repetitions(repetitions)
      ->ReportAggregatesOnly(true);
}

int run(int argc, char** argv, void (*register_cases)()) {
  benchmark::Initialize(&argc, argv);
  register_cases();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace kartograf::bench
