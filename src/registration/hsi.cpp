#include "kartograf/registration/hsi.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace kartograf::registration {

HueSaturation hue_saturation(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  const double R = r, G = g, B = b;
  HueSaturation out;
  const double sum = R + G + B;
  if (sum > 0) out.saturation = 1.0 - 3.0 * std::min({R, G, B}) / sum;
  const double radicand = (R - G) * (R - G) + (R - B) * (G - B);  // 0 only for grey
  if (radicand <= 0) return out;
  const double cosine = ((R - G) + (R - B)) / (2.0 * std::sqrt(radicand));
  const double angle = std::acos(std::clamp(cosine, -1.0, 1.0)) * (180.0 / std::numbers::pi);
  out.has_hue = true;
  out.hue_deg = B > G ? 360.0 - angle : angle;
  if (out.hue_deg >= 360.0) out.hue_deg = 0.0;
  return out;
}

HsiCode quantize(const HueSaturation& value) {
  const auto hue =
      value.has_hue
          ? static_cast<std::uint32_t>(std::lround(value.hue_deg * kHueCodes / 360.0)) % kHueCodes
          : kNoHue;
  const auto saturation = static_cast<std::uint32_t>(
      std::lround(std::clamp(value.saturation, 0.0, 1.0) * kSaturationMax));
  return static_cast<HsiCode>(hue | saturation << 8);
}

double hue_degrees(HsiCode code) {
  return hue_code(code) * 360.0 / kHueCodes;
}

double saturation_value(HsiCode code) {
  return static_cast<double>(saturation_code(code)) / kSaturationMax;
}

std::span<const HsiCode> hsi_table() {
  static const std::vector<HsiCode> table = [] {
    std::vector<HsiCode> entries(std::size_t{1} << 24);
    for (std::uint32_t packed = 0; packed < entries.size(); ++packed) {
      entries[packed] = quantize(hue_saturation(packed & 0xff, (packed >> 8) & 0xff, packed >> 16));
    }
    return entries;
  }();
  return table;
}

}  // namespace kartograf::registration
