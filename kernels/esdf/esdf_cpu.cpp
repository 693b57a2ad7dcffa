// CPU wrapper of kernels/esdf/esdf.h.
#include "compute/cpu/cpu_kernel.hpp"
#include "kernels/esdf/esdf.h"

namespace kartograf::kernels {

namespace {

using compute::detail::CpuDispatch;
using compute::detail::for_each_item;

void seed(const CpuDispatch& call) {
  const auto params = call.params_as<EsdfParams>();
  const auto* cells = call.buffer<const uint>(0);
  auto* squared = call.buffer<int64_t>(1);
  for_each_item(call, [&](uint i) {
    if (i < params.count) squared[i] = esdf_seed_value(cells[i], params);
  });
}

void envelope(const CpuDispatch& call) {
  const auto params = call.params_as<EsdfParams>();
  const auto* line_in = call.buffer<const int64_t>(0);
  auto* line_out = call.buffer<int64_t>(1);
  auto* apex = call.buffer<uint>(2);
  auto* start_num = call.buffer<int64_t>(3);
  auto* start_den = call.buffer<int64_t>(4);
  for_each_item(call, [&](uint line) {
    if (line < params.count)
      esdf_envelope_line(line_in, line_out, apex, start_num, start_den, line, params);
  });
}

void write(const CpuDispatch& call) {
  const auto params = call.params_as<EsdfParams>();
  const auto* squared = call.buffer<const int64_t>(0);
  const auto* cells = call.buffer<const uint>(1);
  auto* esdf = call.buffer<float>(2);
  for_each_item(call, [&](uint i) {
    if (i < params.count) esdf[i] = esdf_value(squared[i], esdf[i], cells[i], params);
  });
}

}  // namespace

void register_esdf_cpu(compute::detail::CpuKernelRegistry& registry) {
  registry.add("esdf_seed", seed);
  registry.add("esdf_envelope", envelope);
  registry.add("esdf_write", write);
}

}  // namespace kartograf::kernels
