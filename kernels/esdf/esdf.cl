// OpenCL wrapper of kernels/esdf/esdf.h.
#include "kernels/esdf/esdf.h"

__kernel void esdf_seed(__global const uint* cells, __global long* squared,
                        const EsdfParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  squared[i] = esdf_seed_value(cells[i], params);
}

__kernel void esdf_envelope(__global const long* line_in, __global long* line_out,
                            __global uint* apex, __global long* start_num,
                            __global long* start_den, const EsdfParams params) {
  const uint line = get_global_id(0);
  if (line >= params.count) return;
  esdf_envelope_line(line_in, line_out, apex, start_num, start_den, line, params);
}

__kernel void esdf_write(__global const long* squared, __global const uint* cells,
                         __global float* esdf, const EsdfParams params) {
  const uint i = get_global_id(0);
  if (i >= params.count) return;
  esdf[i] = esdf_value(squared[i], esdf[i], cells[i], params);
}
