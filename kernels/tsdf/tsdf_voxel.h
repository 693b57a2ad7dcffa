// A voxel of the truncated signed distance field (kernels/tsdf/tsdf.h). Apart, so that a shader
// can declare its voxel buffer before it includes the rule that reads the buffer.
#ifndef KARTOGRAF_KERNELS_TSDF_VOXEL_H
#define KARTOGRAF_KERNELS_TSDF_VOXEL_H
#include "shaders/prelude.h"

KG_RULES_BEGIN

KG_STRUCT_BEGIN(TsdfVoxel)
float tsdf;    // signed distance / truncation, in [-1, 1]; + in front of the surface
float weight;  // 0: never observed
uint color;    // mean colour, 0xBBGGRR
KG_STRUCT_END(TsdfVoxel)

KG_RULES_END

#endif
