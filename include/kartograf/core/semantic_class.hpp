#pragma once
// The semantic classes of the metric-semantic map (method M2) and of the synthetic world's ground
// truth. The numeric values are stored in files (semantic PNGs, JSON): never renumber them.
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "kartograf/core/image.hpp"

namespace kartograf {

enum class SemanticClass : std::uint8_t {
  unknown = 0,
  floor = 1,
  wall = 2,
  ceiling = 3,
  door = 4,
  furniture = 5,
};

inline constexpr int kSemanticClassCount = 6;

inline constexpr std::array<std::string_view, kSemanticClassCount> kSemanticClassNames = {
    "unknown", "floor", "wall", "ceiling", "door", "furniture"};

inline constexpr std::string_view to_string(SemanticClass c) {
  return kSemanticClassNames[static_cast<std::size_t>(c)];
}

inline std::optional<SemanticClass> parse_semantic_class(std::string_view name) {
  for (std::size_t i = 0; i < kSemanticClassNames.size(); ++i) {
    if (kSemanticClassNames[i] == name) return static_cast<SemanticClass>(i);
  }
  return std::nullopt;
}

using SemanticImage = Image<SemanticClass>;

}  // namespace kartograf
