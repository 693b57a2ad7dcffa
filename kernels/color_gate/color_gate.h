// Colour gate (rules in include/kartograf/registration/color_gate.hpp). Per pair, from the two
// colours' HSI codes (hue code | saturation code << 8, include/kartograf/registration/hsi.hpp):
// the packed differences d = bit 0: a pair, bit 1: both have a hue, bits 8..15 dH, bits 16..23 dS
// (0 for entries that are not pairs). The sums over all pairs are sums of integers, exact in double
// in any order; the gate's test dS * pairs > factor * sum dS is one rounding, so every backend
// decides alike.
#ifndef KARTOGRAF_KERNELS_COLOR_GATE_H
#define KARTOGRAF_KERNELS_COLOR_GATE_H
#include "kernels/reduce_rows/reduce_rows.h"
#include "shaders/prelude.h"

// The differences pass is the first pass of a row reduction.
#define KG_COLOR_GATE_DIFFERENCES_LOCAL_X KG_REDUCTION_GROUP
#define KG_COLOR_GATE_APPLY_LOCAL_X 64
// The sums, in this order: pairs, sum dS, hue pairs, sum dH.
#define KG_COLOR_GATE_SUMS 4
#define KG_COLOR_GATE_NO_HUE 255u     // the hue code of grey (kNoHue)
#define KG_COLOR_GATE_HUE_CODES 255u  // hue codes 0..254 cover the circle (kHueCodes)

KG_RULES_BEGIN

KG_PARAMS_BEGIN(ColorGateDifferencesParams)
KG_PARAM(uint, pair_count)  // entries of the correspondence buffer
KG_PARAM(uint, target_count)
KG_PARAMS_END(ColorGateDifferencesParams)

KG_PARAMS_BEGIN(ColorGateApplyParams)
KG_PARAM(uint, pair_count)
KG_PARAM(uint, use_hue)
KG_PARAM(uint, use_saturation)
KG_PARAM(float, mean_factor)
KG_PARAMS_END(ColorGateApplyParams)

KG_INLINE uint color_gate_code_distance(uint a, uint b) {
  return a > b ? a - b : b - a;
}

// The packed differences of a pair whose colours have the HSI codes a and b.
KG_INLINE uint color_gate_pair_differences(uint a, uint b) {
  const uint ds = color_gate_code_distance(a >> 8, b >> 8);
  const uint ha = a & 0xffu;
  const uint hb = b & 0xffu;
  if (ha == KG_COLOR_GATE_NO_HUE || hb == KG_COLOR_GATE_NO_HUE) return 1u | (ds << 16);  // grey
  const uint dh = color_gate_code_distance(ha, hb);  // circular: the shorter way round
  return 3u | (min(dh, KG_COLOR_GATE_HUE_CODES - dh) << 8) | (ds << 16);
}

// The HSI table's 2-byte entries (hsi.hpp) as each language reads them: GLSL has no 16-bit
// buffers, so the shader reads them packed two per 32-bit word.
#if defined(VULKAN)
#define KG_HSI_TABLE_WORD uint
#define kg_hsi_code(table, rgb) \
  ((table[((rgb)&0xffffffu) >> 1] >> ((((rgb)&0xffffffu) & 1u) * 16u)) & 0xffffu)
#elif defined(__OPENCL_C_VERSION__)
#define KG_HSI_TABLE_WORD ushort
#define kg_hsi_code(table, rgb) KG_UINT(table[(rgb)&0xffffffu])
#else
#define KG_HSI_TABLE_WORD std::uint16_t
#define kg_hsi_code(table, rgb) KG_UINT(table[(rgb)&0xffffffu])
#endif

// The differences pass's rule reads its buffers (a GLSL shader declares them and defines
// KG_COLOR_GATE_DIFFERENCES_BUFFERS before including this file).
#if !defined(VULKAN) || defined(KG_COLOR_GATE_DIFFERENCES_BUFFERS)
// The packed differences of source entry i (0 when it is not a pair).
KG_INLINE uint color_gate_entry_differences(KG_BUFFER_PARAM(const uint, source_colors)
                                                KG_BUFFER_PARAM(const uint, target_colors)
                                                    KG_BUFFER_PARAM(const int, correspondences)
                                                        KG_BUFFER_PARAM(const KG_HSI_TABLE_WORD,
                                                                        table) uint i,
                                            ColorGateDifferencesParams p) {
  const int j = correspondences[i];
  if (j < 0 || KG_UINT(j) >= p.target_count) return 0u;
  return color_gate_pair_differences(kg_hsi_code(table, source_colors[i]),
                                     kg_hsi_code(table, target_colors[j]));
}
#endif

// What packed differences d add to sum `slot` (0 for an entry that is not a pair).
KG_INLINE uint color_gate_sum_term(uint d, uint slot) {
  return slot == 0u   ? (d & 1u)
         : slot == 1u ? (d >> 16)
         : slot == 2u ? ((d >> 1) & 1u)
                      : ((d >> 8) & 0xffu);
}

// Whether the gate rejects the pair with packed differences d, given the four sums.
KG_INLINE bool color_gate_rejects(uint d, double pairs, double sum_ds, double hue_pairs,
                                  double sum_dh, ColorGateApplyParams p) {
  if ((d & 1u) == 0u) return false;
  const double factor = KG_DOUBLE(p.mean_factor);
  const bool saturation_far =
      p.use_saturation != 0u && KG_DOUBLE(d >> 16) * pairs > factor * sum_ds;
  const bool hue_far = p.use_hue != 0u && (d & 2u) != 0u &&
                       KG_DOUBLE((d >> 8) & 0xffu) * hue_pairs > factor * sum_dh;
  return saturation_far || hue_far;
}

KG_RULES_END

#endif
