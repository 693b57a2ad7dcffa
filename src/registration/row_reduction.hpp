#pragma once
// The second pass of the device reductions (ICP sums, colour gate): the per-work-group rows that
// a first pass wrote are added into one row, on the device (shaders/reduce_rows.comp).
#include <cstdint>

#include "kartograf/compute/buffer.hpp"

namespace kartograf::registration {

// Work-group size of every first pass that feeds it (KG_REDUCTION_GROUP in shaders/common.glsl).
inline constexpr std::uint32_t kReductionGroupSize = 64;

// result[c] = sum over r < row_count of rows[r * column_count + c], in a fixed order.
void reduce_rows(const compute::Context& context, const compute::Buffer<double>& rows,
                 compute::Buffer<double>& result, std::uint32_t row_count,
                 std::uint32_t column_count);

}  // namespace kartograf::registration
