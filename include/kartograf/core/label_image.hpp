#pragma once
// Per-pixel integer labels: plane ids, room ids, segment ids. 0 means "no label" by convention;
// 16 bits so that they round-trip through 16-bit PNG files.
#include <cstdint>

#include "kartograf/core/image.hpp"

namespace kartograf {

using Label = std::uint16_t;
using LabelImage = Image<Label>;
inline constexpr Label kUnlabeled = 0;

}  // namespace kartograf
