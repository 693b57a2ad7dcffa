#pragma once
// The second pass of the device reductions (ICP sums, colour gate): the per-work-group rows that
// a first pass wrote are added into one row (kernels/reduce_rows/).
#include <cstdint>

#include "kartograf/compute/buffer.hpp"
#include "kernels/reduce_rows/reduce_rows.h"

namespace kartograf::registration {

// Work-group size of every first pass that feeds it.
inline constexpr std::uint32_t kReductionGroupSize = KG_REDUCTION_GROUP;

// result[c] = sum over r < row_count of rows[r * column_count + c], in a fixed order (on the CPU,
// row order).
void reduce_rows(const compute::Context& context, const compute::Buffer<double>& rows,
                 compute::Buffer<double>& result, std::uint32_t row_count,
                 std::uint32_t column_count);

}  // namespace kartograf::registration
