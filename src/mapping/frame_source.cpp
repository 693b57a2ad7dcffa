#include "kartograf/mapping/frame_source.hpp"

#include <chrono>
#include <future>
#include <utility>

namespace kartograf::mapping {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Loaded {
  registration::RgbdImages images;
  double seconds = 0;
};

}  // namespace

FrameLoopTiming for_each_frame(
    const FrameSource& source, std::size_t first, std::size_t last,
    const std::function<void(std::size_t, registration::RgbdImages&)>& visit) {
  FrameLoopTiming timing;
  const auto loop_start = Clock::now();
  const auto load = [&source](std::size_t i) {
    const auto start = Clock::now();
    Loaded loaded{source.frame(i), 0};
    loaded.seconds = seconds_since(start);
    return loaded;
  };
  std::future<Loaded> next;
  if (first < last) next = std::async(std::launch::async, load, first);
  for (std::size_t i = first; i < last; ++i) {
    const auto wait_start = Clock::now();
    Loaded current = next.get();  // rethrows a loading error
    timing.waiting_seconds += seconds_since(wait_start);
    timing.load_seconds += current.seconds;
    if (i + 1 < last) next = std::async(std::launch::async, load, i + 1);
    try {
      visit(i, current.images);
    } catch (...) {
      if (next.valid()) next.wait();  // the prefetch still reads `source`
      throw;
    }
  }
  timing.wall_seconds = seconds_since(loop_start);
  return timing;
}

}  // namespace kartograf::mapping
