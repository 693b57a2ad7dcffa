#pragma once
// A first pass of kernels/reduce_rows/reduce_rows.h on the CPU: compute::detail::for_each_chunk's
// chunks each sum their items into a row; store_chunk_rows writes those rows as the dispatch's
// `row_count` partial rows so that reduce_rows, adding rows in order, adds the chunk rows in chunk
// order (any extra chunks are added into row 0 first; rows without a chunk are 0, which adds
// nothing). The total is then exactly that of adding the chunk rows one after the other.
#include <algorithm>
#include <cstddef>
#include <span>

namespace kartograf::kernels {

template <class ChunkRow>
void store_chunk_rows(std::span<const ChunkRow> chunk_rows, std::size_t column_count,
                      std::size_t row_count, double* partials) {
  std::fill(partials, partials + row_count * column_count, 0.0);
  const std::size_t into_first_row =
      chunk_rows.size() > row_count ? chunk_rows.size() - row_count : 0;
  for (std::size_t chunk = 0; chunk < chunk_rows.size(); ++chunk) {
    double* row = partials + (std::max(chunk, into_first_row) - into_first_row) * column_count;
    for (std::size_t k = 0; k < column_count; ++k) row[k] += chunk_rows[chunk].sums[k];
  }
}

}  // namespace kartograf::kernels
