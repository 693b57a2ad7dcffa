#include "measure.hpp"

#include <algorithm>
#include <chrono>

namespace kartograf::gpu_check {

namespace {
constexpr double kSlowCallMs = 20.0;
constexpr int kSlowCallRepetitions = 5;
}  // namespace

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

Samples measure(const compute::Context& context, const Repetitions& repetitions,
                const std::function<void()>& call) {
  Repetitions counts = repetitions;
  const auto first = std::chrono::steady_clock::now();
  call();
  context.finish();
  const double first_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - first).count();
  if (first_ms > kSlowCallMs) counts = {1, std::min(repetitions.timed, kSlowCallRepetitions)};
  for (int i = 1; i < counts.warm_up; ++i) call();
  context.finish();
  context.take_device_timings();  // the warm-up's
  Samples samples;
  const bool timestamps = context.device_info().limits.device_timestamps;
  for (int i = 0; i < counts.timed; ++i) {
    const auto start = std::chrono::steady_clock::now();
    call();
    context.finish();
    const auto stop = std::chrono::steady_clock::now();
    samples.wall_ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    const std::vector<compute::DeviceTiming> timings = context.take_device_timings();
    if (!timestamps || timings.empty()) continue;
    double total = 0;
    std::map<std::string, double> per_command;
    for (const compute::DeviceTiming& timing : timings) {
      total += timing.milliseconds;
      per_command[timing.command] += timing.milliseconds;
    }
    samples.device_ms.push_back(total);
    for (const auto& [name, ms] : per_command) samples.command_ms[name].push_back(ms);
  }
  return samples;
}

}  // namespace kartograf::gpu_check
