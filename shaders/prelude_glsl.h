// Vulkan GLSL's side of shaders/prelude.h.
#ifndef KARTOGRAF_SHADERS_PRELUDE_GLSL_H
#define KARTOGRAF_SHADERS_PRELUDE_GLSL_H

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#define KG_RULES_BEGIN
#define KG_RULES_END
#define KG_INLINE
#define KG_FORCE_INLINE

#define float3 vec3
#define float4 vec4
#define uint2 uvec2
#define int2 ivec2
#define double3 dvec3

#define KG_FLOAT3(x, y, z) vec3(x, y, z)
#define KG_FLOAT4(x, y, z, w) vec4(x, y, z, w)
#define KG_FLOAT4_XYZ_W(v, w) vec4(v, w)
#define KG_FLOAT(x) float(x)
#define KG_UINT(x) uint(x)
#define KG_INT(x) int(x)
#define KG_DOUBLE(x) double(x)
#define KG_DOUBLE3(x, y, z) dvec3(x, y, z)
#define KG_INT64(x) int64_t(x)
#define KG_UINT64(x) uint64_t(x)
// Round half to even by hand: Mesa's lavapipe (22.3.6, LLVM 15, on an AMD EPYC host) rounded
// roundEven(double) down, and the segment moments' fixed-point sums came out ~2^-31 low per point
// against the CPU's (2026-12-08).
int64_t kg_round_even_int64(double x) {
  const double lower = floor(x);
  const double rest = x - lower;
  int64_t rounded = int64_t(lower);
  if (rest > 0.5 || (rest == 0.5 && (rounded & int64_t(1)) != int64_t(0))) rounded += int64_t(1);
  return rounded;
}

// A function on 64-bit integers that the CPU may also instantiate with a wider type.
#define KG_WIDE_INT_TEMPLATE
#define kg_wide_int int64_t

// An array the function adds to: the module-scope array (per invocation) that the rule declares
// with KG_ACCUMULATOR_STORAGE, so that no array is copied in and out on every call.
#define KG_ACCUMULATOR_STORAGE(type, name, size) type name[size];
#define KG_ACCUMULATOR(type, name, size)
#define KG_ACCUMULATOR_ARG(name)
#define KG_STRUCT_BEGIN(name) struct name {
#define KG_STRUCT_END(name) };

#define kg_fabs(x) abs(x)
#define kg_rsqrt(x) inversesqrt(x)
#define kg_isnan(x) isnan(x)
#define kg_xyz(v) (v).xyz

#define KG_NAN uintBitsToFloat(0x7fc00000u)
#define KG_INFINITY uintBitsToFloat(0x7f800000u)
#define KG_BOTH(a, b) ((a) && (b))

// Atomics on a buffer's element (the 64-bit ones need GL_EXT_shader_atomic_int64 in the shader).
#define kg_atomic_add_u32(buffer, index, value) atomicAdd(buffer[index], value)
#define kg_atomic_add_i64(buffer, index, value) atomicAdd(buffer[index], value)
#define kg_atomic_max_u32(buffer, index, value) atomicMax(buffer[index], value)
#define kg_atomic_cas_u64(buffer, index, compare, value) atomicCompSwap(buffer[index], compare, value)

// Work-group procedures (device code, kernels/work_group/): the lane and the group, a barrier on
// shared memory, shared arrays at module scope (the procedure's own KG_SHARED_STORAGE; KG_SHARED
// and KG_SHARED_ARG expand to nothing) and an array passed in by value.
#define KG_LANE gl_LocalInvocationID.x
#define KG_GROUP gl_WorkGroupID.x
#define KG_GROUP_BARRIER() barrier()
#define KG_SHARED_STORAGE(type, name, size) shared type name[size];
#define KG_SHARED(type, name)
#define KG_SHARED_ARG(name)
#define KG_IN_ARRAY(type, name, size) type name[size]

// No fused multiply-add in the value a declaration marks (GLSL's `precise`).
#define KG_PRECISE precise

// A rule that reads a buffer: GLSL cannot pass one, so the shader declares the buffer under the
// parameter's name before it includes the rule, and both macros expand to nothing.
#define KG_BUFFER_PARAM(type, name)
#define KG_BUFFER_ARG(name)

// A parameter block is a struct; the shader's push-constant block holds one, named `params`.
#define KG_PARAMS_BEGIN(name) struct name {
#define KG_PARAM(type, field) type field;
#define KG_PARAMS_END(name) };
#define KG_PUSH_PARAMS(name) layout(push_constant) uniform name##Block { name params; }

#endif
