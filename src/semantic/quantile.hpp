#pragma once
// Order statistics shared by the semantic layer's measurements.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace kartograf::semantic::detail {

// The value at `fraction` (0..1) of the sorted values: rank fraction * (n - 1), rounded down.
// Reorders `values` (nth_element); needs at least one value.
inline double quantile(std::vector<double>& values, double fraction) {
  const auto k = static_cast<std::ptrdiff_t>(fraction * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<std::size_t>(k)];
}

}  // namespace kartograf::semantic::detail
