#include "plane_throughput.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <iostream>
#include <ostream>
#include <string>
#include <thread>

#include "peer_report.hpp"

namespace kartograf::peer {
namespace {

// One thread's instance and its prepared calls (untimed), the first already made once.
struct Stream {
  PlaneMethod instance;
  std::vector<PlaneRun> runs;
  std::size_t frames_done = 0;
  Clock::time_point end;
  std::exception_ptr failure;
};

// Whole rounds over the stream's frames, starting at `first`, until min_time has passed.
void run_stream(Stream& stream, std::size_t first, Clock::time_point start, double min_time) {
  try {
    const std::size_t count = stream.runs.size();
    do {
      for (std::size_t i = 0; i < count; ++i) stream.runs[(first + i) % count].call();
      stream.frames_done += count;
    } while (seconds_since(start) < min_time);
  } catch (...) {
    stream.failure = std::current_exception();
  }
  stream.end = Clock::now();
}

// Frames a second over `frames` with `stream_count` threads started together.
double frames_per_second(const PlaneMethod& method, const std::vector<const PlaneFrame*>& frames,
                         int stream_count, double min_time) {
  std::vector<Stream> streams(static_cast<std::size_t>(stream_count));
  for (Stream& stream : streams) {
    stream.instance = method.another();
    for (const PlaneFrame* frame : frames) stream.runs.push_back(stream.instance.prepare(*frame));
    stream.runs.front().call();  // warm-up: the instance's buffers and scratch
  }
  // The threads wait for one start, so that none runs alone while the others are being made.
  std::atomic<bool> go{false};
  Clock::time_point start;
  std::vector<std::thread> threads;
  for (std::size_t s = 0; s < streams.size(); ++s) {
    threads.emplace_back([&, s] {
      while (!go.load(std::memory_order_acquire)) std::this_thread::yield();
      run_stream(streams[s], s * frames.size() / streams.size(), start, min_time);
    });
  }
  start = Clock::now();
  go.store(true, std::memory_order_release);
  for (std::thread& thread : threads) thread.join();
  std::size_t total = 0;
  Clock::time_point last = start;
  for (const Stream& stream : streams) {
    if (stream.failure) std::rethrow_exception(stream.failure);
    total += stream.frames_done;
    last = std::max(last, stream.end);
  }
  return static_cast<double>(total) / std::chrono::duration<double>(last - start).count();
}

std::vector<const PlaneFrame*> frames_of(const std::vector<PlaneFrame>& frames,
                                         PlaneDataset dataset) {
  std::vector<const PlaneFrame*> chosen;
  for (const PlaneFrame& frame : frames) {
    if (frame.dataset == dataset) chosen.push_back(&frame);
  }
  return chosen;
}

}  // namespace

void print_plane_throughput(std::ostream& out, const std::vector<PlaneMethod>& methods,
                            const std::vector<PlaneFrame>& frames,
                            const ThroughputOptions& options) {
  if (options.streams < 1) return;
  const std::string n = std::to_string(options.streams);
  out << "\nFrames at a time (frames/s; each of " << n
      << " threads extracts its own frames with its own instance, every frame of the data set in "
         "whole rounds for at least "
      << fixed(options.min_time, 1)
      << " s; beside it the same runner with one thread; throughput, not one frame's latency):\n\n"
      << "| method |";
  for (const PlaneDataset dataset : kPlaneDatasets)
    out << " " << to_string(dataset) << ": 1 | " << to_string(dataset) << ": " << n << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < 2 * std::size(kPlaneDatasets); ++i) out << "---:|";
  out << "\n";
  for (const PlaneMethod& method : methods) {
    if (!method.another) continue;
    std::cerr << "  " << method.name << ", frames at a time\n";
    out << "| " << method.name << " |";
    for (const PlaneDataset dataset : kPlaneDatasets) {
      const std::vector<const PlaneFrame*> chosen = frames_of(frames, dataset);
      if (chosen.empty()) {
        out << " - | - |";
        continue;
      }
      for (const int streams : {1, options.streams}) {
        out << " " << fixed(frames_per_second(method, chosen, streams, options.min_time), 0)
            << " |";
      }
    }
    out << "\n";
  }
}

}  // namespace kartograf::peer
