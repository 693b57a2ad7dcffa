// The whole `kartograf map` pipeline (pipeline/mapper.hpp) on 300 frames of 640x480, on
// every available backend (Google Benchmark, one iteration each: a run takes seconds).
//   map_pipeline/<backend>/7scenes: ../shared/data/7scenes_redkitchen (300 frames, read from disk
//       as the CLI reads them, prefetched on a second thread), stages as counters (seconds).
// KARTOGRAF_DATA_DIR overrides the data folder; KARTOGRAF_BENCH_BACKENDS=cpu,... the backends.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "bench_support.hpp"
#include "kartograf/formats/sequence_detect.hpp"
#include "kartograf/pipeline/mapper.hpp"
#include "kartograf/pipeline/sequence_frame_source.hpp"

namespace kartograf {
namespace {

std::filesystem::path data_dir() {
  const char* configured = std::getenv("KARTOGRAF_DATA_DIR");
  return configured && *configured ? configured : KARTOGRAF_DEFAULT_DATA_DIR;
}

void map_pipeline(benchmark::State& state, compute::BackendKind backend) {
  const std::filesystem::path folder = data_dir() / "7scenes_redkitchen";
  if (!std::filesystem::exists(folder)) {
    state.SkipWithError(("no " + folder.string()).c_str());
    return;
  }
  const io::OpenedSequence opened = io::open_sequence(folder);
  const compute::Context context = compute::Context(bench::context_options(backend));
  pipeline::MapPipelineResult result;
  for (auto _ : state) {
    const pipeline::SequenceFrameSource source(*opened.sequence, 300);
    result = pipeline::run_map_pipeline(context, source);
  }
  state.counters["frames"] = static_cast<double>(result.poses.size());
  state.counters["frames_per_s"] = result.poses.size() / result.total_seconds();
  for (const pipeline::StageTiming& t : result.timings) state.counters[t.stage + "_s"] = t.seconds;
  state.counters["rooms"] = static_cast<double>(result.rooms.records.size());
}

void register_cases() {
  for (const compute::BackendKind backend : bench::backends_to_run()) {
    benchmark::RegisterBenchmark(bench::case_name("map_pipeline", backend, "7scenes").c_str(),
                                 map_pipeline, backend)
        ->Iterations(1)
        ->Unit(benchmark::kSecond)
        ->UseRealTime();
  }
}

}  // namespace
}  // namespace kartograf

int main(int argc, char** argv) {
  return kartograf::bench::run(argc, argv, kartograf::register_cases);
}
