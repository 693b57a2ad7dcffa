// CPU wrapper of kernels/reduce_rows/reduce_rows.h: each column's rows added in row order.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/reduce_rows/reduce_rows.h"

namespace kartograf::kernels {

namespace {

void reduce_rows(const compute::detail::CpuDispatch& call) {
  const auto params = call.params_as<ReduceRowsParams>();
  const auto* rows = call.buffer<const double>(0);
  auto* result = call.buffer<double>(1);
  for (std::size_t column = 0; column < params.column_count; ++column) {
    double sum = 0.0;
    for (std::size_t row = 0; row < params.row_count; ++row) {
      sum += rows[row * params.column_count + column];
    }
    result[column] = sum;
  }
}

}  // namespace

void register_reduce_rows_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("reduce_rows", reduce_rows);
}

}  // namespace kartograf::kernels
