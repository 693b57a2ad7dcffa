#version 450
// Vulkan wrapper of kernels/icp_sums/icp_sums.h: the point-to-plane normal equations
// (kernels/icp_sums/icp_sums.glsl).
#extension GL_GOOGLE_include_directive : require
#define KG_ICP_WITH_NORMALS
#include "kernels/icp_sums/icp_sums.glsl"
