#include "compute/cpu/wide_lanes.hpp"

#include <atomic>

namespace kartograf::compute::detail {

namespace {

std::atomic<bool> wide_allowed{true};

bool processor_has_avx2() {
#if KARTOGRAF_WIDE_LANES
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

}  // namespace

bool wide_lanes_enabled() {
  static const bool available = processor_has_avx2();
  return available && wide_allowed.load(std::memory_order_relaxed);
}

void allow_wide_lanes(bool allowed) {
  wide_allowed.store(allowed, std::memory_order_relaxed);
}

}  // namespace kartograf::compute::detail
