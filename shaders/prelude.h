// The language every kernel rule (kernels/<operation>/<operation>.h) is written in: the subset that
// C++, Vulkan GLSL and OpenCL C share, with the few differences mapped by one prelude per language.
// A rule header includes this file, then declares its parameter blocks (KG_PARAMS_*) and its
// per-element functions (KG_INLINE, with the vocabulary below); the shader, the OpenCL kernel and
// the CPU wrapper include the rule and differ only in how they load and store memory.
//
// The vocabulary (see docs/architecture.md, "Writing a kernel rule once"):
//   types     uint, int, int64_t, uint64_t, float, double, bool, float3, float4, uint2, int2,
//             double3 (C++: kartograf::kernels); kg_wide_int (int64_t, or wider on the CPU) in a
//             function declared after KG_WIDE_INT_TEMPLATE
//   build     KG_FLOAT3(x, y, z), KG_FLOAT4(x, y, z, w), KG_FLOAT4_XYZ_W(v3, w), KG_DOUBLE3(x, y, z)
//   convert   KG_FLOAT(x), KG_UINT(x), KG_INT(x), KG_DOUBLE(x), KG_INT64(x), KG_UINT64(x),
//             kg_round_even_int64(double) (round half to even)
//   math      dot, cross, min, max, clamp, sqrt, floor, kg_fabs, kg_rsqrt, kg_isnan, kg_xyz(v);
//             KG_PRECISE before a declaration: no fused multiply-add in its value (OpenCL also
//             needs `#pragma OPENCL FP_CONTRACT OFF` in the function, see prelude_opencl.h)
//   atomics   kg_atomic_add_u32, kg_atomic_add_i64, kg_atomic_max_u32 (buffer, index, value),
//             kg_atomic_cas_u64(buffer, index, compare, value) -> old value; on KG_BUFFER_PARAMs
//   logic     KG_BOTH(a, b): a and b without a branch (C++: &, so that CPU loops vectorise)
//   constants KG_NAN, KG_INFINITY, KG_INVALID_POINT (all-NaN float4)
//   functions KG_INLINE before each function (KG_FORCE_INLINE: a large per-item one); arguments
//             by value (GLSL has no pointers), except
//             KG_ACCUMULATOR(type, name, size): a leading parameter, the array the function adds to
//             (a row of sums), declared once before with KG_ACCUMULATOR_STORAGE(type, name, size)
//             (GLSL: a module-scope array per invocation, never copied per call; C, C++: nothing,
//             the caller's array); KG_ACCUMULATOR_ARG(name) passes it; no comma after either
//   buffers   KG_BUFFER_PARAM(type, name) opens a function's parameters with a buffer it reads or
//             writes (GLSL: the shader's buffer of that name, declared before the rule's #include),
//             KG_BUFFER_ARG(name) passes one on; no comma after either
//   groups    device code only (kernels/work_group/): KG_LANE, KG_GROUP, KG_GROUP_BARRIER(),
//             KG_SHARED_STORAGE(type, name, size) (GLSL: the shared array; OpenCL: the kernel
//             declares it), KG_SHARED(type, name) / KG_SHARED_ARG(name) (a leading parameter, like
//             a buffer), KG_IN_ARRAY(type, name, size) (an array read, passed by value in GLSL)
//   params    KG_PARAMS_BEGIN(Name) KG_PARAM(uint|int|float, field)... KG_PARAMS_END(Name)
//   structs   KG_STRUCT_BEGIN(Name) type field; ... KG_STRUCT_END(Name) (values passed and returned)
//   scopes    KG_RULES_BEGIN / KG_RULES_END around a rule header's declarations
// Include guards, not #pragma once: the OpenCL sources are joined into one program at build time.
#ifndef KARTOGRAF_SHADERS_PRELUDE_H
#define KARTOGRAF_SHADERS_PRELUDE_H

#if defined(__cplusplus)
#include "shaders/prelude_cpp.hpp"
#elif defined(__OPENCL_C_VERSION__)
#include "shaders/prelude_opencl.h"
#elif defined(VULKAN)
#include "shaders/prelude_glsl.h"
#else
#error "kernel rules compile as C++, OpenCL C or Vulkan GLSL"
#endif

#define KG_INVALID_POINT KG_FLOAT4(KG_NAN, KG_NAN, KG_NAN, KG_NAN)

#endif
