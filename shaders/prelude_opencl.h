// OpenCL C's side of shaders/prelude.h.
#ifndef KARTOGRAF_SHADERS_PRELUDE_OPENCL_H
#define KARTOGRAF_SHADERS_PRELUDE_OPENCL_H

#define KG_RULES_BEGIN
#define KG_RULES_END
#define KG_INLINE inline
// PoCL keeps calls to large `inline` functions (their arrays then live in memory, and the
// work-group loop cannot vectorize): a kernel's per-item rule is forced inline.
#define KG_FORCE_INLINE inline __attribute__((always_inline))

#define KG_FLOAT3(x, y, z) ((float3)(x, y, z))
#define KG_FLOAT4(x, y, z, w) ((float4)(x, y, z, w))
#define KG_FLOAT4_XYZ_W(v, w) ((float4)(v, w))
#define KG_FLOAT(x) ((float)(x))
#define KG_UINT(x) ((uint)(x))
#define KG_INT(x) ((int)(x))
#define KG_DOUBLE(x) ((double)(x))
#define KG_DOUBLE3(x, y, z) ((double3)(x, y, z))
#define KG_INT64(x) ((long)(x))
#define KG_UINT64(x) ((ulong)(x))
#define kg_round_even_int64(x) convert_long_rte(x)
typedef long int64_t;
typedef ulong uint64_t;

// A function on 64-bit integers that the CPU may also instantiate with a wider type.
#define KG_WIDE_INT_TEMPLATE
#define kg_wide_int long

#define KG_ACCUMULATOR_STORAGE(type, name, size)
#define KG_ACCUMULATOR(type, name, size) type *name,
#define KG_ACCUMULATOR_ARG(name) name,
#define KG_STRUCT_BEGIN(name) typedef struct {
#define KG_STRUCT_END(name) } name;

#define kg_fabs(x) fabs(x)
#define kg_rsqrt(x) rsqrt(x)
#define kg_isnan(x) isnan(x)
#define kg_xyz(v) (v).xyz

#define KG_NAN NAN
#define KG_INFINITY INFINITY
#define KG_BOTH(a, b) ((a) && (b))

// Atomics on a buffer's element (the 64-bit ones need cl_khr_int64_base_atomics, see common.cl).
#define kg_atomic_add_u32(buffer, index, value) atomic_add(&(buffer)[index], value)
#define kg_atomic_add_i64(buffer, index, value) atom_add(&(buffer)[index], value)
#define kg_atomic_max_u32(buffer, index, value) atomic_max(&(buffer)[index], value)
#define kg_atomic_cas_u64(buffer, index, compare, value) \
  atom_cmpxchg(&(buffer)[index], compare, value)

// Work-group procedures (device code, kernels/work_group/): the kernel declares each shared array
// (`__local type name[size]`) and passes it on with KG_SHARED_ARG.
#define KG_LANE get_local_id(0)
#define KG_GROUP get_group_id(0)
#define KG_GROUP_BARRIER() barrier(CLK_LOCAL_MEM_FENCE)
#define KG_SHARED_STORAGE(type, name, size)
#define KG_SHARED(type, name) __local type* name,
#define KG_SHARED_ARG(name) name,
#define KG_IN_ARRAY(type, name, size) const type* name

// GLSL's `precise`: OpenCL C forbids the contraction instead with `#pragma OPENCL FP_CONTRACT OFF`
// at the top of the function's body (inside `#if defined(__OPENCL_C_VERSION__)`: at file scope it
// would reach every kernel joined after it).
#define KG_PRECISE

// A rule that reads a buffer takes it as a leading parameter: KG_BUFFER_PARAM(const float4,
// points) declares it (with its comma), KG_BUFFER_ARG(points) passes it.
#define KG_BUFFER_PARAM(type, name) __global type* name,
#define KG_BUFFER_ARG(name) name,

// A parameter block is a typedef'd struct, passed by value as the kernel's last argument.
#define KG_PARAMS_BEGIN(name) typedef struct {
#define KG_PARAM(type, field) type field;
#define KG_PARAMS_END(name) } name;

#endif
