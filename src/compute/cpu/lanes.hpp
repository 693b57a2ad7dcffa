#pragma once
// Four floats or ints that the compiler keeps in one SIMD register (the GCC and Clang vector
// extension: SSE on x86-64, NEON on ARM, without target-specific code), for CPU loops whose
// sums or choices the auto-vectorizer does not find.
#include <cstdint>

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

}  // namespace kartograf::compute::detail
