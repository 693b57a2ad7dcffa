#pragma once
// The cells mode's pixel scoring (cell_planes.cpp's ScoreRule::best) eight pixels at a time in
// AVX2 (compute/cpu/wide_lanes.hpp): the same float operations per lane, so the same choices and
// squared distances, bit for bit, as the four-lane code and the devices' rule. Call only where
// compute::detail::wide_lanes_enabled().
#include <cstdint>

#include "kartograf/core/point_image.hpp"

namespace kartograf::segmentation::detail {

// A rectangle's candidate planes (count of them) and the rule's constants.
struct WideScoreInputs {
  float distance_base, distance_per_z2, min_facing;
  const float *nx, *ny, *nz, *offset;
  int count;
};

// Pixels x0 .. x1 - 1 ((x1 - x0) a multiple of 8) of `rows` rows, `stride` points apart from
// `first_row`: per pixel the index of the candidate it takes (-1: none) and its squared distance
// to it (1 where none), row after row from choices[0] and distance2[0] on. Rows are independent,
// so the processor overlaps one row's chain of comparisons over the candidates with the next's.
void wide_rows_choices(const WideScoreInputs& in, const Point4f* first_row, int stride, int rows,
                       int x0, int x1, std::int32_t* choices, float* distance2);

// The row's choices (width a multiple of 8, at most 64) per candidate k < count: bit j of bits[k]
// is set where pixel j took k, and squared[k] sums those pixels' squared distances (in float,
// eight lanes then across them: another order than the four-lane tally's, which only the
// planes' output RMS sees).
void wide_row_tally(const std::int32_t* choices, const float* distance2, int width, int count,
                    std::uint64_t* bits, float* squared);

}  // namespace kartograf::segmentation::detail
