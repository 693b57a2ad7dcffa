#include "kartograf/geometry/distance_transform.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

namespace kartograf::geometry {

namespace {

constexpr std::int64_t kNoZero = -1;

// A rational number num / den with den > 0: where two parabolas meet, compared exactly.
struct Fraction {
  std::int64_t num = 0, den = 1;
};

bool at_most(const Fraction& a, const Fraction& b) {
  return a.num * b.den <= b.num * a.den;
}

// The lower envelope of the parabolas (q - p)^2 + f[p] over the p with f[p] >= 0, evaluated at
// every q: out[q] = min_p (q - p)^2 + f[p], or kNoZero everywhere when no f[p] is >= 0.
class LineEnvelope {
 public:
  void apply(std::span<const std::int64_t> f, std::span<std::int64_t> out) {
    apex_.resize(f.size());
    start_.resize(f.size());
    std::size_t count = 0;
    for (std::int64_t q = 0; q < static_cast<std::int64_t>(f.size()); ++q) {
      if (f[q] < 0) continue;
      if (count == 0) {
        apex_[count++] = q;
        continue;
      }
      // The newest parabola hides those whose part of the envelope starts after it takes over.
      Fraction from = meet(f, apex_[count - 1], q);
      while (count > 1 && at_most(from, start_[count - 1])) {
        --count;
        from = meet(f, apex_[count - 1], q);
      }
      apex_[count] = q;
      start_[count++] = from;
    }
    if (count == 0) {
      std::fill(out.begin(), out.end(), kNoZero);
      return;
    }
    std::size_t j = 0;
    for (std::int64_t q = 0; q < static_cast<std::int64_t>(out.size()); ++q) {
      while (j + 1 < count && start_[j + 1].num <= q * start_[j + 1].den) ++j;
      const std::int64_t d = q - apex_[j];
      out[q] = d * d + f[apex_[j]];
    }
  }

 private:
  // Where the parabola of q (> p) starts to lie below that of p.
  static Fraction meet(std::span<const std::int64_t> f, std::int64_t p, std::int64_t q) {
    return {(f[q] + q * q) - (f[p] + p * p), 2 * (q - p)};
  }

  std::vector<std::int64_t> apex_;
  std::vector<Fraction> start_;
};

}  // namespace

Image<std::int64_t> squared_distance_to_zero(const Image<std::uint8_t>& mask) {
  const int width = mask.width(), height = mask.height();
  Image<std::int64_t> result(width, height);
  if (result.empty()) return result;
  LineEnvelope envelope;
  // Columns: the squared distance to the nearest zero in the same column.
  std::vector<std::int64_t> line(static_cast<std::size_t>(height));
  std::vector<std::int64_t> column(static_cast<std::size_t>(height));
  for (int x = 0; x < width; ++x) {
    for (int y = 0; y < height; ++y) line[y] = mask(x, y) == 0 ? 0 : kNoZero;
    envelope.apply(line, column);
    for (int y = 0; y < height; ++y) result(x, y) = column[y];
  }
  // Rows: the nearest of the columns' nearest zeros.
  std::vector<std::int64_t> row(static_cast<std::size_t>(width));
  for (int y = 0; y < height; ++y) {
    const std::span<std::int64_t> in(&result(0, y), static_cast<std::size_t>(width));
    envelope.apply(in, row);
    std::copy(row.begin(), row.end(), in.begin());
  }
  return result;
}

Image<float> distance_to_zero(const Image<std::uint8_t>& mask) {
  const Image<std::int64_t> squared = squared_distance_to_zero(mask);
  Image<float> distance(mask.width(), mask.height());
  for (std::size_t i = 0; i < squared.size(); ++i) {
    const std::int64_t s = squared.pixels()[i];
    distance.pixels()[i] =
        s < 0 ? std::numeric_limits<float>::infinity() : std::sqrt(static_cast<float>(s));
  }
  return distance;
}

}  // namespace kartograf::geometry
