#pragma once
// Four floats or ints that the compiler keeps in one SIMD register (the GCC and Clang vector
// extension: SSE on x86-64, NEON on ARM, without target-specific code), for CPU loops whose
// sums or choices the auto-vectorizer does not find.
#include <cstdint>
#include <cstring>
#include <limits>

namespace kartograf::compute::detail {

using Lanes = float __attribute__((vector_size(16)));
using LaneMask = std::int32_t __attribute__((vector_size(16)));  // comparisons: 0 or -1

inline Lanes splat(float value) {
  return Lanes{value, value, value, value};
}
inline LaneMask splat(std::int32_t value) {
  return LaneMask{value, value, value, value};
}

// Per lane: a where the mask is set, else b.
template <class Vector>
Vector select(LaneMask mask, Vector a, Vector b) {
  return reinterpret_cast<Vector>((mask & reinterpret_cast<LaneMask>(a)) |
                                  (~mask & reinterpret_cast<LaneMask>(b)));
}

// Per lane std::min(a, b) (b < a ? b : a) and std::max(a, b) (a < b ? b : a), NaN lanes
// included: SSE's own instructions where there are (they choose the same way), else a select.
inline Lanes min_of(Lanes a, Lanes b) {
#if defined(__SSE__)
  return __builtin_ia32_minps(b, a);  // b < a ? b : a
#else
  return select(b < a, b, a);
#endif
}
inline Lanes max_of(Lanes a, Lanes b) {
#if defined(__SSE__)
  return __builtin_ia32_maxps(b, a);  // b > a ? b : a
#else
  return select(a < b, b, a);
#endif
}

// The last lane of `previous` followed by the first three of `next`: each lane's left neighbour
// along a row read four at a time.
inline Lanes shift_in(Lanes previous, Lanes next) {
#if defined(__clang__)
  return __builtin_shufflevector(previous, next, 3, 4, 5, 6);
#else
  return __builtin_shuffle(previous, next, LaneMask{3, 4, 5, 6});
#endif
}

// Four points of four floats each (x, y, z, w), as read from memory, turned into their x, y and z
// lanes (w dropped): a 4 x 4 transpose in six shuffles instead of twelve lane inserts.
struct XyzLanes {
  Lanes x, y, z;
};
inline XyzLanes transpose_xyz(Lanes a, Lanes b, Lanes c, Lanes d) {
#if defined(__clang__)
  const Lanes ab_low = __builtin_shufflevector(a, b, 0, 4, 1, 5);   // ax bx ay by
  const Lanes cd_low = __builtin_shufflevector(c, d, 0, 4, 1, 5);   // cx dx cy dy
  const Lanes ab_high = __builtin_shufflevector(a, b, 2, 6, 3, 7);  // az bz aw bw
  const Lanes cd_high = __builtin_shufflevector(c, d, 2, 6, 3, 7);  // cz dz cw dw
  return {__builtin_shufflevector(ab_low, cd_low, 0, 1, 4, 5),
          __builtin_shufflevector(ab_low, cd_low, 2, 3, 6, 7),
          __builtin_shufflevector(ab_high, cd_high, 0, 1, 4, 5)};
#else
  using Index = LaneMask;
  const Lanes ab_low = __builtin_shuffle(a, b, Index{0, 4, 1, 5});
  const Lanes cd_low = __builtin_shuffle(c, d, Index{0, 4, 1, 5});
  const Lanes ab_high = __builtin_shuffle(a, b, Index{2, 6, 3, 7});
  const Lanes cd_high = __builtin_shuffle(c, d, Index{2, 6, 3, 7});
  return {__builtin_shuffle(ab_low, cd_low, Index{0, 1, 4, 5}),
          __builtin_shuffle(ab_low, cd_low, Index{2, 3, 6, 7}),
          __builtin_shuffle(ab_high, cd_high, Index{0, 1, 4, 5})};
#endif
}

// The x, y and z lanes of `count` (<= 4) consecutive points of four floats each from `first`
// (NaN in the lanes past count); four points by the transpose, fewer one by one.
inline XyzLanes load_xyz(const float* first, int count) {
  if (count >= 4) {
    Lanes a, b, c, d;
    std::memcpy(&a, first, sizeof a), std::memcpy(&b, first + 4, sizeof b);
    std::memcpy(&c, first + 8, sizeof c), std::memcpy(&d, first + 12, sizeof d);
    return transpose_xyz(a, b, c, d);
  }
  const Lanes none = splat(std::numeric_limits<float>::quiet_NaN());
  XyzLanes p{none, none, none};
  for (int j = 0; j < count; ++j) {
    p.x[j] = first[4 * j], p.y[j] = first[4 * j + 1], p.z[j] = first[4 * j + 2];
  }
  return p;
}

// Asks for the cache lines of [begin, end) before they are read: the next row of a rectangle in
// an image lies a whole image row away, where the hardware has not fetched yet. A hint only.
inline void prefetch_lines(const void* begin, const void* end) {
  constexpr std::uintptr_t kLine = 64;
  const std::uintptr_t last = reinterpret_cast<std::uintptr_t>(end);
  for (std::uintptr_t line = reinterpret_cast<std::uintptr_t>(begin) & ~(kLine - 1); line < last;
       line += kLine)
    __builtin_prefetch(reinterpret_cast<const void*>(line));
}

}  // namespace kartograf::compute::detail
