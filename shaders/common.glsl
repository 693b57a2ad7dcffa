// Shared by every Kartograf compute shader (included with GL_GOOGLE_include_directive).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

// The quiet NaN that marks an invalid point or normal.
#define kNaN uintBitsToFloat(0x7fc00000u)
#define kInvalidPoint vec4(kNaN)

bool is_valid_point(vec4 p) { return !isnan(p.x); }
