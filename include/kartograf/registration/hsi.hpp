#pragma once
// Hue and saturation of the HSI colour model (docs/methods.md M3 step 3; paper eq. 1-3), exactly
// and through the paper's lookup table of all 2^24 RGB values. Intensity is not used: H and S stay
// stable when the illumination changes, which is why the colour gate (color_gate.hpp) uses them.
//
// Formulas, for 8-bit R, G, B:
//   H = arccos( ((R-G) + (R-B)) / (2 sqrt((R-G)^2 + (R-B)(G-B))) ) in degrees, 360 - H when B > G
//   S = 1 - 3 min(R,G,B) / (R+G+B)
// Eq. 1 as printed reads (1/2)(R-G) + (R-B) in the numerator, which leaves [-1, 1] (pure red would
// give 1.5); this is the standard form it abbreviates. Undefined values: grey (R = G = B) has no
// hue (the denominator is 0) and black has S = 0.
//
// Table entries are 2 bytes (32 MiB for 2^24 colours), indexed by the packed colour
// r | g << 8 | b << 16 (CloudView::colors, core/color.hpp pack_rgb):
//   low byte   hue code h = round(H * 255 / 360) mod 255, in 0..254 (bins of 360/255 = 1.41 deg),
//              or kNoHue (255) for grey;
//   high byte  saturation code s = round(S * 255), in 0..255.
// Quantisation error: |H - h * 360/255| <= 0.706 deg (circularly), |S - s/255| <= 1/510.
#include <cstdint>
#include <span>

namespace kartograf::registration {

struct HueSaturation {
  bool has_hue = false;   // false for grey (R = G = B)
  double hue_deg = 0;     // [0, 360); 0 without hue
  double saturation = 0;  // [0, 1]
};

// Eq. 1-3 in double.
HueSaturation hue_saturation(std::uint8_t r, std::uint8_t g, std::uint8_t b);

using HsiCode = std::uint16_t;                   // hue code | saturation code << 8
inline constexpr std::uint32_t kHueCodes = 255;  // hue codes 0..254 cover the circle
inline constexpr std::uint32_t kNoHue = 255;     // hue code of grey
inline constexpr std::uint32_t kSaturationMax = 255;

HsiCode quantize(const HueSaturation& value);
inline std::uint32_t hue_code(HsiCode code) {
  return code & 0xffu;
}
inline std::uint32_t saturation_code(HsiCode code) {
  return static_cast<std::uint32_t>(code) >> 8;
}
// The centre of a code's bin.
double hue_degrees(HsiCode code);
double saturation_value(HsiCode code);

// The table of quantize(hue_saturation(r, g, b)) for every colour. Built on first use (~0.5 s on
// one core), once per process, thread-safe; lives until exit.
std::span<const HsiCode> hsi_table();
inline HsiCode hsi_lookup(std::span<const HsiCode> table, std::uint32_t packed_rgb) {
  return table[packed_rgb & 0xffffffu];
}
// The colour gate's distances of two codes are its kernel rule's (kernels/color_gate/color_gate.h).

}  // namespace kartograf::registration
