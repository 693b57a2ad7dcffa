// Two-pass reductions without atomics, reproducible run to run: a first pass (the ICP sums, the
// colour gate) writes one row of sums per work-group; reduce_rows adds the rows into one, column by
// column, in a fixed order. On the CPU the rows are added in row order, so a first pass that writes
// its chunks' sums in chunk order gets the chunks' total in that order.
#ifndef KARTOGRAF_KERNELS_REDUCE_ROWS_H
#define KARTOGRAF_KERNELS_REDUCE_ROWS_H
#include "shaders/prelude.h"

// The work-group size of every first pass, and of reduce_rows.
#define KG_REDUCTION_GROUP 64
// The most sums one row carries (the point-to-plane ICP row has 32).
#define KG_MAX_SUMS 32
#define KG_REDUCE_ROWS_LOCAL_X KG_REDUCTION_GROUP

KG_RULES_BEGIN

KG_PARAMS_BEGIN(ReduceRowsParams)
KG_PARAM(uint, row_count)
KG_PARAM(uint, column_count)  // one work-group per column
KG_PARAMS_END(ReduceRowsParams)

KG_RULES_END

#endif
