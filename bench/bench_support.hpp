#pragma once
// What the device benchmark binaries share: the backends to measure (KARTOGRAF_BENCH_BACKENDS),
// a context on one of them, the "<operation>/<backend>/<size>" case names, the timing settings
// and main(). Each binary only describes its inputs and what one call does.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "kartograf/compute/backend.hpp"
#include "kartograf/compute/context.hpp"

namespace kartograf::bench {

// Every available backend that KARTOGRAF_BENCH_BACKENDS (e.g. "vulkan,opencl") lists, all of
// them when it is unset or empty. A listed backend that is unavailable is skipped with its reason
// on stderr, so one binary runs on any machine.
std::vector<compute::BackendKind> backends_to_run();

// Options for a context on exactly `backend` (no validation layer: these are timings).
compute::ContextParams context_options(compute::BackendKind backend);

// "<operation>/<backend>/<size>", e.g. "normals/vulkan/640x480": the name of every case, so that
// --benchmark_filter selects the same way in every binary.
std::string case_name(const std::string& operation, compute::BackendKind backend,
                      const std::string& size);

// Wall-clock milliseconds over `repetitions` repetitions, reporting only the aggregates (mean,
// median, stddev); the caller adds MinTime or Iterations.
benchmark::internal::Benchmark* repeated(benchmark::internal::Benchmark* bench, int repetitions);

// Google Benchmark's main, with `register_cases` run after the flags are parsed.
int run(int argc, char** argv, void (*register_cases)());

}  // namespace kartograf::bench
