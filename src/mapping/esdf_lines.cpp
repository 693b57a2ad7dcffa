#include "mapping/esdf_lines.hpp"

#include "kartograf/compute/kernel.hpp"
#include "kernels/esdf/esdf.h"

namespace kartograf::mapping::detail {

namespace {

constexpr compute::KernelSpec kEsdfEnvelopeKernel{"esdf_envelope", KG_ESDF_LOCAL_X, 1};

std::uint32_t narrow(std::size_t n) {
  return static_cast<std::uint32_t>(n);
}

}  // namespace

void EsdfScratch::reserve(std::size_t cells) {
  if (a.size() >= cells) return;
  a = compute::Buffer<std::int64_t>(*context, cells);
  b = compute::Buffer<std::int64_t>(*context, cells);
  start_num = compute::Buffer<std::int64_t>(*context, cells);
  start_den = compute::Buffer<std::int64_t>(*context, cells);
  apex = compute::Buffer<std::uint32_t>(*context, cells);
}

void esdf_envelope(const EsdfLines& lines, const compute::Buffer<std::int64_t>& in,
                   compute::Buffer<std::int64_t>& out, EsdfScratch& scratch) {
  if (lines.count == 0) return;
  kernels::EsdfParams q{};
  q.count = narrow(lines.count);
  q.line_cells = narrow(lines.cells);
  q.line_stride = narrow(lines.line_stride);
  q.lines_per_plane = narrow(lines.lines_per_plane);
  q.plane_stride = narrow(lines.plane_stride);
  q.cell_stride = narrow(lines.cell_stride);
  compute::dispatch(*scratch.context, kEsdfEnvelopeKernel,
                    {in, out, scratch.apex, scratch.start_num, scratch.start_den}, q,
                    {compute::groups_for(lines.count, KG_ESDF_LOCAL_X), 1});
}

}  // namespace kartograf::mapping::detail
