#include "kartograf/segmentation/lab_color.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "compute/cpu/lanes.hpp"
#include "compute/cpu_parallel.hpp"

namespace kartograf::segmentation {

namespace {

using compute::detail::LaneMask;
using compute::detail::Lanes;
using compute::detail::select;
using compute::detail::splat;

// sRGB -> XYZ (D65) and the D65 reference white, from IEC 61966-2-1.
constexpr double kRgbToXyz[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                    {0.2126729, 0.7151522, 0.0721750},
                                    {0.0193339, 0.1191920, 0.9503041}};
constexpr double kWhite[3] = {0.95047, 1.0, 1.08883};
constexpr double kEpsilon = 216.0 / 24389.0;  // CIE's (6/29)^3
constexpr double kKappa = 24389.0 / 27.0;

double srgb_to_linear(std::uint8_t v) {
  const double c = v / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double lab_f(double t) {
  return t > kEpsilon ? std::cbrt(t) : (kKappa * t + 16.0) / 116.0;
}

// The white-normalised XYZ rows, so that t = row . linear_rgb directly.
double normalised_matrix(int row, int col) {
  return kRgbToXyz[row][col] / kWhite[row];
}

// Tables for to_lab: the gamma decoding (exact per 8-bit value) and lab_f sampled on [0, kFMax]
// with linear interpolation (error < 1e-5 in f, i.e. < 1e-3 in L*, a*, b*).
struct LabTables {
  static constexpr int kFSamples = 8192;
  static constexpr float kFMax = 1.0001f;  // normalised X, Y, Z never exceed 1 for sRGB input
  std::array<float, 256> linear{};
  std::array<float, kFSamples + 2> f{};
  float matrix[3][3]{};

  LabTables() {
    for (int v = 0; v < 256; ++v)
      linear[v] = static_cast<float>(srgb_to_linear(static_cast<std::uint8_t>(v)));
    for (int i = 0; i < kFSamples + 2; ++i)
      f[i] = static_cast<float>(lab_f(i * double{kFMax} / kFSamples));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) matrix[r][c] = static_cast<float>(normalised_matrix(r, c));
  }

  // lab_f of four values: t clamped to [0, kFMax], the two samples around it interpolated.
  Lanes interpolated_f(Lanes t) const {
    t = select(t < splat(0.0f), splat(0.0f), t);  // std::max(t, 0)
    const Lanes x = select(splat(kFMax) < t, splat(kFMax), t) * splat(kFSamples / kFMax);
    LaneMask i = __builtin_convertvector(x, LaneMask);  // truncation, as static_cast<int>
    i = select(splat(kFSamples) < i, splat(kFSamples), i);
    const Lanes w = x - __builtin_convertvector(i, Lanes);
    Lanes at, next;
    for (int k = 0; k < 4; ++k) at[k] = f[i[k]], next[k] = f[i[k] + 1];
    return at + w * (next - at);
  }
};

const LabTables& lab_tables() {
  static const LabTables tables;
  return tables;
}

// srgb_to_linear of every 8-bit value, kept (the same doubles, without three pow calls a colour).
const std::array<double, 256>& linear_table() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> values{};
    for (int v = 0; v < 256; ++v) values[v] = srgb_to_linear(static_cast<std::uint8_t>(v));
    return values;
  }();
  return table;
}

}  // namespace

Eigen::Vector3f rgb_to_lab(const Rgb8& rgb) {
  const std::array<double, 256>& table = linear_table();
  const double linear[3] = {table[rgb[0]], table[rgb[1]], table[rgb[2]]};
  double f[3];
  for (int r = 0; r < 3; ++r) {
    double t = 0.0;
    for (int c = 0; c < 3; ++c) t += normalised_matrix(r, c) * linear[c];
    f[r] = lab_f(t);
  }
  return {static_cast<float>(116.0 * f[1] - 16.0), static_cast<float>(500.0 * (f[0] - f[1])),
          static_cast<float>(200.0 * (f[1] - f[2]))};
}

namespace {

// Round half to even of |v| <= 2^22 without a libm call: adding 1.5 * 2^23 leaves no fraction
// bits, so the float addition rounds (as roundEven / convert_int_rte do).
std::int16_t to_code(float value) {
  constexpr float kShift = 12582912.0f;  // 1.5 * 2^23
  constexpr float kClamp = 255.0f;
  const float scaled = std::min(std::max(value, -kClamp), kClamp) * kLabCodeScale;
  return static_cast<std::int16_t>((scaled + kShift) - kShift);
}

// to_code of four values, lane by lane the same float operations.
LaneMask to_codes(Lanes value) {
  constexpr float kShift = 12582912.0f;  // 1.5 * 2^23
  constexpr float kClamp = 255.0f;
  value = select(value < splat(-kClamp), splat(-kClamp), value);  // std::max(value, -kClamp)
  const Lanes scaled = select(splat(kClamp) < value, splat(kClamp), value) * splat(kLabCodeScale);
  return __builtin_convertvector((scaled + splat(kShift)) - splat(kShift), LaneMask);
}

// L*, a* and b* of `count` (<= 4) pixels from `in`, lane by lane (the lanes past count hold the
// last pixel's).
struct LabLanes {
  Lanes l, a, b;
};
LabLanes lab_lanes(const LabTables& tables, const Rgb8* in, int count) {
  Lanes rgb[3];
  for (int k = 0; k < 4; ++k) {
    const Rgb8& pixel = in[std::min(k, count - 1)];
    for (int c = 0; c < 3; ++c) rgb[c][k] = tables.linear[pixel[c]];
  }
  Lanes f[3];
  for (int row = 0; row < 3; ++row) {
    const float* m = tables.matrix[row];
    f[row] =
        tables.interpolated_f(splat(m[0]) * rgb[0] + splat(m[1]) * rgb[1] + splat(m[2]) * rgb[2]);
  }
  return {splat(116.0f) * f[1] - splat(16.0f), splat(500.0f) * (f[0] - f[1]),
          splat(200.0f) * (f[1] - f[2])};
}

// Converts every pixel with the tables, four at a time (on the CPU backend's threads); `store`
// receives the first pixel's index, how many of the four lanes are pixels, and their lanes.
template <class Store>
void convert_pixels(const RgbImage& rgb, Store&& store) {
  const LabTables& tables = lab_tables();
  const Rgb8* in = rgb.data();
  compute::detail::for_each_chunk(
      rgb.size(), rgb.size(), [&](std::size_t begin, std::size_t end, std::size_t) {
        for (std::size_t i = begin; i < end; i += 4) {
          const int count = static_cast<int>(std::min<std::size_t>(4, end - i));
          store(i, count, lab_lanes(tables, in + i, count));
        }
      });
}

}  // namespace

LabImage to_lab(const RgbImage& rgb) {
  LabImage lab(rgb.width(), rgb.height());
  Eigen::Vector4f* out = lab.data();
  convert_pixels(rgb, [out](std::size_t i, int count, const LabLanes& lab) {
    for (int k = 0; k < count; ++k)
      out[i + k] = Eigen::Vector4f(lab.l[k], lab.a[k], lab.b[k], 0.0f);
  });
  return lab;
}

LabCodeImage to_lab_codes(const RgbImage& rgb) {
  LabCodeImage codes;
  to_lab_codes(rgb, codes);
  return codes;
}

void to_lab_codes(const RgbImage& rgb, LabCodeImage& codes) {
  if (codes.width() != rgb.width() || codes.height() != rgb.height())
    codes = LabCodeImage(rgb.width(), rgb.height());
  LabCode* out = codes.data();
  convert_pixels(rgb, [out](std::size_t i, int count, const LabLanes& lab) {
    const LaneMask l = to_codes(lab.l), a = to_codes(lab.a), b = to_codes(lab.b);
    for (int k = 0; k < count; ++k) {
      out[i + k] = {static_cast<std::int16_t>(l[k]), static_cast<std::int16_t>(a[k]),
                    static_cast<std::int16_t>(b[k]), 1};
    }
  });
}

LabCodeImage to_lab_codes(const LabImage& lab) {
  LabCodeImage codes(lab.width(), lab.height());
  for (std::size_t i = 0; i < lab.size(); ++i) {
    const Eigen::Vector4f& v = lab.data()[i];
    const bool valid = v.head<3>().allFinite();
    codes.data()[i] =
        valid ? LabCode{to_code(v.x()), to_code(v.y()), to_code(v.z()), 1} : LabCode{0, 0, 0, 0};
  }
  return codes;
}

}  // namespace kartograf::segmentation
