#include "kartograf/core/connected_components.hpp"

#include <limits>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf {

LabelImage label_connected_components(const Image<std::uint8_t>& mask,
                                      const ComponentParams& options) {
  require(options.min_pixels >= 1, "label_connected_components: min_pixels must be >= 1, got " +
                                       std::to_string(options.min_pixels));
  const int width = mask.width(), height = mask.height();
  LabelImage labels(width, height, kUnlabeled);
  std::vector<std::uint8_t> visited(mask.size(), 0);
  std::vector<int> region;  // pixel indices of the region being grown; reused
  std::vector<int> stack;
  // Edge neighbours first; the diagonal ones count only with eight-connectivity.
  static constexpr int kOffsets[8][2] = {{1, 0}, {-1, 0}, {0, 1},  {0, -1},
                                         {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  const int neighbour_count = options.connectivity == Connectivity::eight ? 8 : 4;
  int next_label = 1;

  for (int start = 0; start < static_cast<int>(mask.size()); ++start) {
    if (mask.pixels()[start] == 0 || visited[start]) continue;
    region.clear();
    stack.assign(1, start);
    visited[start] = 1;
    while (!stack.empty()) {
      const int index = stack.back();
      stack.pop_back();
      region.push_back(index);
      const int x = index % width, y = index / width;
      for (int k = 0; k < neighbour_count; ++k) {
        const int nx = x + kOffsets[k][0], ny = y + kOffsets[k][1];
        if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
        const int neighbour = ny * width + nx;
        if (mask.pixels()[neighbour] == 0 || visited[neighbour]) continue;
        visited[neighbour] = 1;
        stack.push_back(neighbour);
      }
    }
    if (static_cast<int>(region.size()) < options.min_pixels) continue;
    require(next_label <= std::numeric_limits<Label>::max(),
            "label_connected_components: more than 65535 regions of >= " +
                std::to_string(options.min_pixels) + " pixels; labels are 16-bit");
    for (int index : region) labels.pixels()[index] = static_cast<Label>(next_label);
    ++next_label;
  }
  return labels;
}

}  // namespace kartograf
