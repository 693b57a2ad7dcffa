// C++'s side of shaders/prelude.h: the shading-language types and functions kernel rules use, in
// namespace kartograf::kernels. Plain float arithmetic in the written order (no fused multiply-add
// unless the compiler's flags allow it), so the CPU is the reference the GPU backends are tested
// against.
#ifndef KARTOGRAF_SHADERS_PRELUDE_CPP_HPP
#define KARTOGRAF_SHADERS_PRELUDE_CPP_HPP

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

#define KG_RULES_BEGIN namespace kartograf::kernels {
#define KG_RULES_END }
#define KG_INLINE inline
#define KG_FORCE_INLINE inline __attribute__((always_inline))

namespace kartograf::kernels {

using uint = std::uint32_t;
using std::int64_t;
using std::uint64_t;

struct float3 {
  float x, y, z;
};
struct float4 {
  float x, y, z, w;
};
struct uint2 {
  uint x, y;
};
struct int2 {
  int x, y;
};
struct double3 {
  double x, y, z;
};
static_assert(sizeof(float4) == 16 && sizeof(float3) == 12, "shading-language vector layout");

inline float3 operator+(float3 a, float3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline float3 operator-(float3 a, float3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline float3 operator-(float3 a) { return {-a.x, -a.y, -a.z}; }
inline float3 operator*(float3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline float3 operator*(float s, float3 a) { return a * s; }
inline float3& operator*=(float3& a, float s) { return a = a * s; }
inline float dot(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float3 cross(float3 a, float3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float3 kg_xyz(float4 v) { return {v.x, v.y, v.z}; }
inline double3 operator+(double3 a, double3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline double3 operator-(double3 a, double3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double3 operator*(double3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double3 operator/(double3 a, double s) { return {a.x / s, a.y / s, a.z / s}; }
inline double dot(double3 a, double3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline double3 cross(double3 a, double3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

using std::clamp;
using std::max;
using std::min;
using std::floor;
using std::sqrt;
inline float kg_fabs(float x) { return std::fabs(x); }
inline double kg_fabs(double x) { return std::fabs(x); }
// The CPU takes the correctly rounded 1 / sqrt(x); GPUs' rsqrt is within a few ulp of it.
inline float kg_rsqrt(float x) { return 1.0f / std::sqrt(x); }
inline bool kg_isnan(float x) { return std::isnan(x); }
// Round half to even, as roundEven / convert_long_rte: adding and subtracting 1.5 * 2^52 rounds
// any |v| < 2^51 to an integer in double arithmetic (fast, inline); larger values take nearbyint.
inline std::int64_t kg_round_even_int64(double v) {
  constexpr double kRoundingShift = 6755399441055744.0;  // 1.5 * 2^52
  if (std::fabs(v) < 2251799813685248.0) {                // 2^51
    return static_cast<std::int64_t>((v + kRoundingShift) - kRoundingShift);
  }
  return static_cast<std::int64_t>(std::nearbyint(v));
}

// Atomics on a buffer's element (relaxed: dispatches are ordered by the backend, not by these).
inline uint kg_atomic_add_u32(uint* buffer, uint index, uint value) {
  return std::atomic_ref<uint>(buffer[index]).fetch_add(value, std::memory_order_relaxed);
}
inline int64_t kg_atomic_add_i64(int64_t* buffer, uint index, int64_t value) {
  return std::atomic_ref<int64_t>(buffer[index]).fetch_add(value, std::memory_order_relaxed);
}
inline uint kg_atomic_max_u32(uint* buffer, uint index, uint value) {
  std::atomic_ref<uint> element(buffer[index]);
  uint old = element.load(std::memory_order_relaxed);
  while (old < value && !element.compare_exchange_weak(old, value, std::memory_order_relaxed)) {
  }
  return old;
}
// Stores value where the element equals compare; returns the element's old value. A plain load
// first: where it differs, the exchange would fail anyway (and a locked instruction is slow).
inline uint64_t kg_atomic_cas_u64(uint64_t* buffer, uint index, uint64_t compare, uint64_t value) {
  std::atomic_ref<uint64_t> element(buffer[index]);
  const uint64_t seen = element.load(std::memory_order_relaxed);
  if (seen != compare) return seen;
  element.compare_exchange_strong(compare, value, std::memory_order_relaxed);
  return compare;
}

}  // namespace kartograf::kernels

#define KG_FLOAT3(x, y, z) (::kartograf::kernels::float3{x, y, z})
#define KG_FLOAT4(x, y, z, w) (::kartograf::kernels::float4{x, y, z, w})
#define KG_FLOAT4_XYZ_W(v, w) (::kartograf::kernels::float4{(v).x, (v).y, (v).z, w})
#define KG_FLOAT(x) static_cast<float>(x)
#define KG_UINT(x) static_cast<::kartograf::kernels::uint>(x)
#define KG_INT(x) static_cast<int>(x)
#define KG_DOUBLE(x) static_cast<double>(x)
#define KG_DOUBLE3(x, y, z) (::kartograf::kernels::double3{x, y, z})
#define KG_INT64(x) static_cast<std::int64_t>(x)
#define KG_UINT64(x) static_cast<std::uint64_t>(x)
// A function on 64-bit integers that the CPU may also instantiate with a wider type (__int128).
#define KG_WIDE_INT_TEMPLATE template <class kg_wide_int>

// An array a function adds to, its leading parameter (see prelude.h).
#define KG_ACCUMULATOR_STORAGE(type, name, size)
#define KG_ACCUMULATOR(type, name, size) type *name,
#define KG_ACCUMULATOR_ARG(name) name,
#define KG_STRUCT_BEGIN(name) struct name {
#define KG_STRUCT_END(name) \
  }                         \
  ;
#define KG_NAN std::numeric_limits<float>::quiet_NaN()
#define KG_INFINITY std::numeric_limits<float>::infinity()
// Both conditions, evaluated without a branch: loops over such rules become vector code.
#define KG_BOTH(a, b) (static_cast<bool>(a) & static_cast<bool>(b))

// GLSL's `precise`: C++ never contracts (-std=c++20 implies -ffp-contract=off).
#define KG_PRECISE

// A rule that reads a buffer takes it as a leading parameter (see prelude_opencl.h).
#define KG_BUFFER_PARAM(type, name) type* name,
#define KG_BUFFER_ARG(name) name,

// A parameter block is a struct of 4-byte scalars: the layout of the shader's push-constant block
// and of the OpenCL struct argument (checked here and by compute::dispatch).
#define KG_PARAMS_BEGIN(name) struct name {
#define KG_PARAM(type, field) \
  type field;                 \
  static_assert(sizeof(type) == 4, "kernel parameters are 4-byte scalars");
#define KG_PARAMS_END(name) \
  }                         \
  ;                         \
  static_assert(alignof(name) == 4 && sizeof(name) % 4 == 0, "kernel parameter block layout");

#endif
