// Depth back-projection: a 16-bit depth value -> the point (x, y, z, 1) in metres, all NaN where
// the value is 0 or outside [min_units, max_units]. The per-pixel factors (u - cx) / fx * m and
// (v - cy) / fy * m (m = metres per unit) are precomputed on the host, once per camera.
#ifndef KARTOGRAF_KERNELS_BACKPROJECT_H
#define KARTOGRAF_KERNELS_BACKPROJECT_H
#include "shaders/prelude.h"

#define KG_BACKPROJECT_LOCAL_X 16
#define KG_BACKPROJECT_LOCAL_Y 16

KG_RULES_BEGIN

KG_PARAMS_BEGIN(BackprojectParams)
KG_PARAM(uint, width)
KG_PARAM(uint, height)
KG_PARAM(uint, min_units)  // valid depth values are min_units..max_units (and never 0)
KG_PARAM(uint, max_units)
KG_PARAM(float, metres_per_unit)
KG_PARAMS_END(BackprojectParams)

// The point of depth value d; all NaN when d is not valid.
KG_INLINE float4 backproject_depth(uint d, float column_factor, float row_factor,
                                   BackprojectParams p) {
  const bool valid = d != 0u && d >= p.min_units && d <= p.max_units;
  // One select: NaN times a factor is NaN, so the invalid point comes out of the products.
  const float z = valid ? KG_FLOAT(d) : KG_NAN;
  return KG_FLOAT4(z * column_factor, z * row_factor, z * p.metres_per_unit, valid ? 1.0f : KG_NAN);
}

KG_RULES_END

#endif
