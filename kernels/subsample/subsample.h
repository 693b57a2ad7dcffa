// Uniform 1-in-k subsampling of an unorganized cloud (contract in
// include/kartograf/geometry/subsample.hpp): output m is input m * k, for the points and, when
// present, the normals and colours.
#ifndef KARTOGRAF_KERNELS_SUBSAMPLE_H
#define KARTOGRAF_KERNELS_SUBSAMPLE_H
#include "shaders/prelude.h"

#define KG_SUBSAMPLE_LOCAL_X 64

KG_RULES_BEGIN

KG_PARAMS_BEGIN(SubsampleParams)
KG_PARAM(uint, out_count)
KG_PARAM(uint, k)
KG_PARAM(uint, has_normals)  // 0: the normal buffers are absent
KG_PARAM(uint, has_colors)   // 0: the colour buffers are absent
KG_PARAMS_END(SubsampleParams)

KG_INLINE uint subsample_source_index(uint m, SubsampleParams p) {
  return m * p.k;
}

KG_RULES_END

#endif
