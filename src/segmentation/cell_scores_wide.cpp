#include "cell_scores_wide.hpp"

#include <cstddef>
#include <cstring>
#include <stdexcept>

#include "compute/cpu/wide_lanes.hpp"

namespace kartograf::segmentation::detail {

#if KARTOGRAF_WIDE_LANES

namespace {

using compute::detail::WideLanes;
using compute::detail::WideMask;

// ScoreRule::best (cell_planes.cpp) on eight pixels: see its comment for the rule.
KG_WIDE_TARGET void eight_choices(const WideScoreInputs& in, const compute::detail::WideXyz& p,
                                  std::int32_t* choices, float* distance2) {
  const WideLanes range2 = p.x * p.x + p.y * p.y + p.z * p.z;
  const WideLanes floor2 = (in.min_facing * in.min_facing) * range2;
  WideLanes best_d2 = WideLanes{} + 1.0f, best_s2 = WideLanes{};  // no candidate yet: 1 / 0
  WideMask choice = WideMask{} - 1;
  for (int k = 0; k < in.count; ++k) {
    const WideLanes along = in.nx[k] * p.x + in.ny[k] * p.y + in.nz[k] * p.z;
    const WideLanes d = along + in.offset[k];
    const WideLanes d2 = d * d, a2 = along * along;
    const WideLanes s2 = a2 > floor2 ? a2 : floor2;
    const WideMask better = d2 * best_s2 < best_d2 * s2;
    best_d2 = better ? d2 : best_d2;
    best_s2 = better ? s2 : best_s2;
    choice = better ? WideMask{} + k : choice;
  }
  const WideLanes base = in.distance_base + in.distance_per_z2 * p.z * p.z;
  const WideMask chosen = best_d2 * range2 < base * base * best_s2 ? choice : WideMask{} - 1;
  std::memcpy(choices, &chosen, sizeof chosen);
  std::memcpy(distance2, &best_d2, sizeof best_d2);
}

KG_WIDE_TARGET void row_choices(const WideScoreInputs& in, const Point4f* row, int x0, int x1,
                                std::int32_t* choices, float* distance2) {
  for (int x = x0; x < x1; x += 8) {
    eight_choices(in, compute::detail::load_eight_xyz(row[x].data()), choices + (x - x0),
                  distance2 + (x - x0));
  }
}

KG_WIDE_TARGET void row_tally(const std::int32_t* choices, const float* distance2, int width,
                              int count, std::uint64_t* bits, float* squared) {
  for (int k = 0; k < count; ++k) {
    WideLanes sum{};
    std::uint64_t taken = 0;
    for (int x = 0; x < width; x += 8) {
      WideMask c;
      WideLanes d2;
      std::memcpy(&c, choices + x, sizeof c), std::memcpy(&d2, distance2 + x, sizeof d2);
      const WideMask mine = c == k;
      taken |= std::uint64_t{compute::detail::wide_mask_bits(mine)} << x;
      sum += mine ? d2 : WideLanes{};
    }
    bits[k] = taken;
    squared[k] = compute::detail::wide_sum(sum);
  }
}

}  // namespace

void wide_row_tally(const std::int32_t* choices, const float* distance2, int width, int count,
                    std::uint64_t* bits, float* squared) {
  row_tally(choices, distance2, width, count, bits, squared);
}

void wide_rows_choices(const WideScoreInputs& in, const Point4f* first_row, int stride, int rows,
                       int x0, int x1, std::int32_t* choices, float* distance2) {
  const int width = x1 - x0;
  for (int r = 0; r < rows; ++r) {
    row_choices(in, first_row + static_cast<std::ptrdiff_t>(r) * stride, x0, x1,
                choices + r * width, distance2 + r * width);
  }
}

#else

void wide_rows_choices(const WideScoreInputs&, const Point4f*, int, int, int, int, std::int32_t*,
                       float*) {
  throw std::logic_error("wide_rows_choices: no AVX2 code in this build");
}

void wide_row_tally(const std::int32_t*, const float*, int, int, std::uint64_t*, float*) {
  throw std::logic_error("wide_row_tally: no AVX2 code in this build");
}

#endif

}  // namespace kartograf::segmentation::detail
