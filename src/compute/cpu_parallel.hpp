#pragma once
// The CPU backend's data parallelism for the hot loops of the operations: a fixed number of
// contiguous chunks, run on KARTOGRAF_CPU_THREADS threads (default 1). Per-chunk results combined in chunk order do
// not depend on the thread count or on scheduling, so sums are identical for any setting.
//
// Why one thread by default: on a machine shared with other work (this project's 2-core build
// hosts), a helper thread descheduled while holding a chunk stalls every join for a time slice;
// 640x480 odometry measured 27 ms per frame on one thread and 35 ms on two there. On a dedicated
// multi-core machine, KARTOGRAF_CPU_THREADS=<cores> shortens the ICP part accordingly.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <string>
#include <thread>
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

// Calls body(begin, end, chunk) for the kCpuChunks contiguous chunks of [0, count); `work` is
// the number of points behind them (e.g. count rows of an image): below ~32k points starting a
// thread (~50 us) costs more than it saves.
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
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t chunk = next++; chunk < kCpuChunks; chunk = next++) run_chunk(chunk);
  };
  std::vector<std::jthread> helpers;
  for (std::size_t t = 1; t < threads; ++t) helpers.emplace_back(worker);
  worker();
}

}  // namespace kartograf::compute::detail
