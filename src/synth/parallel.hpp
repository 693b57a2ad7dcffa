#pragma once
// Row-parallel loops for the renderer and the laser scanner. Each row is computed by exactly one
// thread and rows do not interact, so results do not depend on the thread count.
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace kartograf::synth::detail {

inline int thread_count(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Calls body(row_begin, row_end) for chunks of rows covering [0, rows).
template <class Body>
void parallel_rows(int rows, int threads, const Body& body) {
  constexpr int kChunk = 8;
  const int workers = std::min(thread_count(threads), (rows + kChunk - 1) / kChunk);
  if (workers <= 1) {
    body(0, rows);
    return;
  }
  std::atomic<int> next{0};
  auto work = [&] {
    for (int begin; (begin = next.fetch_add(kChunk)) < rows;)
      body(begin, std::min(rows, begin + kChunk));
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < workers; ++i) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace kartograf::synth::detail
