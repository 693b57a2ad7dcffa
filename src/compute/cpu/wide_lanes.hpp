#pragma once
// Eight floats or ints in one 256-bit register, for the few CPU loops where AVX2 halves the work
// of lanes.hpp's four (a block row of eight pixels in one step). Only code compiled for AVX2
// (KG_WIDE_TARGET) may use these types, and only after wide_lanes_enabled() said yes: the same
// binary runs on x86-64 processors without AVX2 and on other architectures, where
// KARTOGRAF_WIDE_LANES is 0 and the four-lane code runs. GCC only for now (its __builtin_shuffle
// and vector conditionals); a Clang build runs the four-lane code.
#include <cstdint>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define KARTOGRAF_WIDE_LANES 1
#define KG_WIDE_TARGET __attribute__((target("avx2")))
#else
#define KARTOGRAF_WIDE_LANES 0
#define KG_WIDE_TARGET
#endif

namespace kartograf::compute::detail {

// Whether this processor runs AVX2 and no one turned the wide code off (allow_wide_lanes).
bool wide_lanes_enabled();
// Tests turn the wide code off to check the four-lane code on the same machine; on by default.
void allow_wide_lanes(bool allowed);

#if KARTOGRAF_WIDE_LANES
using WideLanes = float __attribute__((vector_size(32)));
using WideMask = std::int32_t __attribute__((vector_size(32)));  // comparisons: 0 or -1
using WideBytes = std::uint8_t __attribute__((vector_size(32)));
using WideShorts = std::uint16_t __attribute__((vector_size(32)));
using HalfBytes = std::uint8_t __attribute__((vector_size(16)));

struct WideXyz {
  WideLanes x, y, z;
};

// Eight consecutive points of four floats (x, y, z, w) from `first` as their x, y and z lanes in
// order: the 128-bit halves paired first (points 0 and 4, 1 and 5, ...), then a 4 x 4 transpose
// within each half (eleven shuffles for eight points).
KG_WIDE_TARGET inline WideXyz load_eight_xyz(const float* first) {
  WideLanes a, b, c, d;
  __builtin_memcpy(&a, first, sizeof a), __builtin_memcpy(&b, first + 8, sizeof b);
  __builtin_memcpy(&c, first + 16, sizeof c), __builtin_memcpy(&d, first + 24, sizeof d);
  using Index = WideMask;
  const WideLanes p04 = __builtin_shuffle(a, c, Index{0, 1, 2, 3, 8, 9, 10, 11});
  const WideLanes p15 = __builtin_shuffle(a, c, Index{4, 5, 6, 7, 12, 13, 14, 15});
  const WideLanes p26 = __builtin_shuffle(b, d, Index{0, 1, 2, 3, 8, 9, 10, 11});
  const WideLanes p37 = __builtin_shuffle(b, d, Index{4, 5, 6, 7, 12, 13, 14, 15});
  const WideLanes xy01 = __builtin_shuffle(p04, p15, Index{0, 8, 1, 9, 4, 12, 5, 13});
  const WideLanes xy23 = __builtin_shuffle(p26, p37, Index{0, 8, 1, 9, 4, 12, 5, 13});
  const WideLanes zw01 = __builtin_shuffle(p04, p15, Index{2, 10, 3, 11, 6, 14, 7, 15});
  const WideLanes zw23 = __builtin_shuffle(p26, p37, Index{2, 10, 3, 11, 6, 14, 7, 15});
  return {__builtin_shuffle(xy01, xy23, Index{0, 1, 8, 9, 4, 5, 12, 13}),
          __builtin_shuffle(xy01, xy23, Index{2, 3, 10, 11, 6, 7, 14, 15}),
          __builtin_shuffle(zw01, zw23, Index{0, 1, 8, 9, 4, 5, 12, 13})};
}

// Bit j: lane j of the mask is set.
KG_WIDE_TARGET inline std::uint32_t wide_mask_bits(WideMask mask) {
  return static_cast<std::uint32_t>(__builtin_ia32_movmskps256(reinterpret_cast<WideLanes>(mask)));
}

// `value` in `previous`'s place followed by lanes 0..6: each lane's left neighbour along a row.
KG_WIDE_TARGET inline WideLanes wide_shift_in(float previous, WideLanes next) {
  const WideLanes left = WideLanes{} + previous;
  return __builtin_shuffle(next, left, WideMask{8, 0, 1, 2, 3, 4, 5, 6});
}

KG_WIDE_TARGET inline float wide_sum(WideLanes v) {
  return ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]));
}
#endif

}  // namespace kartograf::compute::detail
