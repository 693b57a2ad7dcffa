#pragma once
// How every part of the peer benchmark times a call and describes the machine, so that the
// registration and plane tables are measured the same way.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace kartograf::peer {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start);
// CPU time of every thread of the process (Open3D's OpenMP workers, the drivers' threads): what a
// call costs when other work shares the cores, where wall time also counts the waiting.
double process_cpu_seconds();

struct TimingOptions {
  double min_time = 0.3;  // seconds of calls per method and input
  int max_calls = 9;
};

struct CallTimes {
  std::vector<double> seconds;      // wall clock, one per call
  std::vector<double> cpu_seconds;  // process CPU time, one per call
};

// Calls `call` until options.min_time seconds have passed (at least once, at most
// options.max_calls times), appending each call's wall and CPU time; returns every call's result.
template <class Call>
auto time_calls(const Call& call, const TimingOptions& options, CallTimes& times) {
  std::vector<decltype(call())> results;
  const Clock::time_point first = Clock::now();
  do {
    const double cpu_start = process_cpu_seconds();
    const Clock::time_point start = Clock::now();
    auto result = call();
    times.seconds.push_back(seconds_since(start));
    times.cpu_seconds.push_back(process_cpu_seconds() - cpu_start);
    results.push_back(std::move(result));
  } while (seconds_since(first) < options.min_time &&
           static_cast<int>(results.size()) < options.max_calls);
  return results;
}

std::string cpu_model();     // /proc/cpuinfo's model name
std::string load_average();  // /proc/loadavg's 1, 5 and 15 minute averages

}  // namespace kartograf::peer
