// Prepended to every Kartograf OpenCL kernel file (all are built as one program): the extensions
// every kernel needs.
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL EXTENSION cl_khr_int64_base_atomics : enable
