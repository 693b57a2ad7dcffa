#version 450
// Vulkan wrapper of kernels/icp_sums/icp_sums.h: the point-to-point sums (kernels/icp_sums/icp_sums.glsl).
#extension GL_GOOGLE_include_directive : require
#include "kernels/icp_sums/icp_sums.glsl"
