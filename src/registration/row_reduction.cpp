#include "registration/row_reduction.hpp"

#include "kartograf/compute/kernel.hpp"
#include "kartograf/core/error.hpp"

namespace kartograf::registration {

namespace {
constexpr compute::KernelSpec kReduceRowsKernel{"reduce_rows", KG_REDUCE_ROWS_LOCAL_X};
}  // namespace

void reduce_rows(const compute::Context& context, const compute::Buffer<double>& rows,
                 compute::Buffer<double>& result, std::uint32_t row_count,
                 std::uint32_t column_count) {
  require(std::size_t{row_count} * column_count <= rows.size() && column_count <= result.size(),
          "reduce_rows: " + std::to_string(row_count) + " x " + std::to_string(column_count) +
              " sums do not fit the buffers");
  compute::dispatch(context, kReduceRowsKernel, {rows, result},
                    kernels::ReduceRowsParams{row_count, column_count}, {column_count, 1});
}

}  // namespace kartograf::registration
