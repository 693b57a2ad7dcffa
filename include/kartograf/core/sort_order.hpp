#pragma once
// The indices that put values in increasing order (an argsort), for reordering several arrays
// that belong together by one of them.
#include <algorithm>
#include <cstddef>
#include <numeric>
#include <span>
#include <vector>

namespace kartograf {

// Indices i_0, i_1, ... with values[i_0] <= values[i_1] <= ...; equal values keep their order.
template <class T>
std::vector<std::size_t> ascending_order(std::span<const T> values) {
  std::vector<std::size_t> order(values.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
  return order;
}

}  // namespace kartograf
