#pragma once
// The CPU backend's data parallelism for the hot loops of the operations: a fixed number of
// contiguous chunks, run on KARTOGRAF_CPU_THREADS threads (default 1). Per-chunk results combined
// in chunk order do not depend on the thread count or on scheduling, so sums are identical for any
// setting.
//
// The helper threads are started once and sleep between calls (cpu_parallel.cpp); starting a
// thread per call, as before 2026-11-29, cost more than the second thread saved: 7-Scenes
// odometry (`kartograf odometry`, 600 frames, this project's 2-core build host) ran at 63 fps on
// two threads against 69 on one; with the kept helpers it runs at 73-76 fps on two. Since
// 2026-12-04 the helpers (and the caller, waiting for them) spin about 50 microseconds before
// sleeping, so that a burst of calls costs no wake-ups: the cells mode's plane extraction on two
// threads 372-376 -> 381-398 frames/s over the plane bench's 28 frames (three runs in turn).
//
// Why one thread by default: on a machine shared with other work (such as those build hosts), a
// helper thread descheduled while holding a chunk stalls every join for a time slice. On a
// dedicated multi-core machine, KARTOGRAF_CPU_THREADS=<cores> shortens the parallel parts.
#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf::compute::detail {

inline constexpr std::size_t kCpuChunks = 8;

// KARTOGRAF_CPU_THREADS (1..kCpuChunks; unset: 1), read at each call so a process can change it.
inline std::size_t configured_cpu_threads() {
  const char* text = std::getenv("KARTOGRAF_CPU_THREADS");
  if (!text || !*text) return 1;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  require(end && *end == '\0' && value >= 1,
          std::string("KARTOGRAF_CPU_THREADS: expected a thread count >= 1, got '") + text + "'");
  return std::min<std::size_t>(static_cast<std::size_t>(value), kCpuChunks);
}

// Runs run_chunk(chunk) for every chunk in [0, kCpuChunks) on `threads` threads: the caller's
// and threads - 1 helpers kept waiting between calls (cpu_parallel.cpp), so that a call costs a
// wake-up instead of starting threads. A call made while the helpers are busy (from a helper, or
// from another thread of the process) runs its chunks on the caller's thread alone; the results
// are the same, as the chunks are. A chunk that throws ends the process on a helper, as on a
// thread of its own; on the caller the exception is thrown on once the helpers are done.
void run_chunks(std::size_t threads, void (*run_chunk)(const void* context, std::size_t chunk),
                const void* context);

// Calls body(begin, end, chunk) for the kCpuChunks contiguous chunks of [0, count); `work` is
// the number of points behind them (e.g. count rows of an image): below ~32k points waking a
// helper costs more than it saves.
template <class Body>
void for_each_chunk(std::size_t count, std::size_t work, Body&& body) {
  const auto run_chunk = [&](std::size_t chunk) {
    body(count * chunk / kCpuChunks, count * (chunk + 1) / kCpuChunks, chunk);
  };
  const std::size_t threads = work < 32768 ? 1 : configured_cpu_threads();
  if (threads <= 1) {
    for (std::size_t chunk = 0; chunk < kCpuChunks; ++chunk) run_chunk(chunk);
    return;
  }
  using RunChunk = decltype(run_chunk);
  run_chunks(
      threads,
      [](const void* context, std::size_t chunk) {
        (*static_cast<const RunChunk*>(context))(chunk);
      },
      &run_chunk);
}

}  // namespace kartograf::compute::detail
