// Shared by every Kartograf compute shader (included with GL_GOOGLE_include_directive).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

// The quiet NaN that marks an invalid point or normal.
#define kNaN uintBitsToFloat(0x7fc00000u)
#define kInvalidPoint vec4(kNaN)

bool is_valid_point(vec4 p) { return !isnan(p.x); }

// Work-group size of the reductions (must equal kReductionGroupSize in src/compute/reduction.hpp).
#define KG_REDUCTION_GROUP 64
// The most sums one reduction row carries (point-to-plane needs 29).
#define KG_MAX_SUMS 32
