#pragma once
// The line pass of the exact Euclidean distance transform on the device (kernels/esdf/esdf.h,
// esdf_envelope), shared by the 2-D ESDF of the band (tsdf_slice.cpp) and the 3-D ESDF
// (esdf_volume.cpp).
#include <cstddef>
#include <cstdint>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/compute/context.hpp"

namespace kartograf::mapping::detail {

// Bytes per cell the transform's buffers take: two squared distances, the envelope's apex and
// crossing (numerator, denominator).
inline constexpr std::size_t kEsdfScratchBytesPerCell = 8 + 8 + 4 + 8 + 8;

// The transform's working buffers, one element per cell; grown, never shrunk.
struct EsdfScratch {
  explicit EsdfScratch(const compute::Context& context) : context(&context) {}
  void reserve(std::size_t cells);

  const compute::Context* context;
  compute::Buffer<std::int64_t> a, b, start_num, start_den;
  compute::Buffer<std::uint32_t> apex;
};

// A set of parallel lines in a dense array: line i's first cell is
// (i / lines_per_plane) x plane_stride + (i % lines_per_plane) x line_stride, its next cells
// cell_stride apart.
struct EsdfLines {
  std::size_t count = 0;
  std::size_t cells = 0;  // per line
  std::size_t line_stride = 0;
  std::size_t lines_per_plane = 0;
  std::size_t plane_stride = 0;
  std::size_t cell_stride = 0;
};

// Squared distances along the lines: out = the lower envelope of in's parabolas on every line.
void esdf_envelope(const EsdfLines& lines, const compute::Buffer<std::int64_t>& in,
                   compute::Buffer<std::int64_t>& out, EsdfScratch& scratch);

}  // namespace kartograf::mapping::detail
