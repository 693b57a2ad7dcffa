#include "kartograf/synth/material.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "kartograf/core/random.hpp"

namespace kartograf::synth {

namespace {

// Random lattice values: one 256 x 256 table (fixed), shifted per seed; it repeats only every 256
// lattice cells (tens of metres), and a lookup is far cheaper than hashing each corner.
struct LatticeTable {
  LatticeTable() {
    for (std::size_t i = 0; i < values.size(); ++i) {
      values[i] = static_cast<float>(unit_interval(mix64(i + 0x6c617474ULL)));
    }
  }
  std::array<float, 256 * 256> values{};
};
const LatticeTable kLattice;

inline std::int64_t floor_to_int(double x) {
  const auto i = static_cast<std::int64_t>(x);
  return i - (x < static_cast<double>(i) ? 1 : 0);
}

double smooth(double t) {
  return t * t * (3.0 - 2.0 * t);
}

double single_octave(double u, double v, std::uint64_t seed) {
  const std::int64_t i = floor_to_int(u);
  const std::int64_t j = floor_to_int(v);
  const double su = smooth(u - static_cast<double>(i));
  const double sv = smooth(v - static_cast<double>(j));
  const auto x0 = static_cast<std::uint64_t>(i) + (seed & 0xff);
  const auto y0 = static_cast<std::uint64_t>(j) + ((seed >> 8) & 0xff);
  const auto x1 = (x0 + 1) & 0xff, row0 = (y0 & 0xff) << 8, row1 = ((y0 + 1) & 0xff) << 8;
  const auto& t = kLattice.values;
  const double a = t[(x0 & 0xff) | row0], b = t[x1 | row0];
  const double c = t[(x0 & 0xff) | row1], d = t[x1 | row1];
  return (a + (b - a) * su) * (1.0 - sv) + (c + (d - c) * su) * sv;
}

}  // namespace

std::string_view to_string(Pattern pattern) {
  switch (pattern) {
    case Pattern::solid:
      return "solid";
    case Pattern::noise:
      return "noise";
    case Pattern::stripes:
      return "stripes";
    case Pattern::checker:
      return "checker";
    case Pattern::wood:
      return "wood";
  }
  return "solid";
}

double value_noise(double u, double v, std::uint64_t seed) {
  return (2.0 * single_octave(u, v, seed) +
          single_octave(2.03 * u + 17.0, 2.03 * v - 5.0, seed + 1)) /
         3.0;
}

Eigen::Vector3d Material::albedo(double u, double v) const {
  const double n = value_noise(u / noise_scale, v / noise_scale, seed);
  const double variation = 1.0 + noise_amplitude * (2.0 * n - 1.0);
  Eigen::Vector3d color = color_a;
  switch (pattern) {
    case Pattern::solid:
      break;
    case Pattern::noise:
      color = color_a + (color_b - color_a) * n;
      break;
    case Pattern::stripes: {
      const double phase = u / period - std::floor(u / period);
      color = phase < 0.5 ? color_a : color_b;
      break;
    }
    case Pattern::checker: {
      const double cu = u / period, cv = v / period;
      const auto iu = static_cast<std::int64_t>(std::floor(cu));
      const auto iv = static_cast<std::int64_t>(std::floor(cv));
      color = ((iu + iv) % 2 == 0) ? color_a : color_b;
      const double grout = 0.015 / period;  // 1.5 cm dark joints
      const double du = cu - std::floor(cu), dv = cv - std::floor(cv);
      if (du < grout || dv < grout) color = 0.45 * color_b;
      break;
    }
    case Pattern::wood: {
      // Grain: bands along u whose phase wanders with low-frequency noise.
      const double wobble = value_noise(u / (4.0 * noise_scale), v / noise_scale, seed + 7);
      const double band =
          0.5 + 0.5 * std::sin(2.0 * std::numbers::pi * (v / period + 1.5 * wobble));
      color = color_a + (color_b - color_a) * band;
      break;
    }
  }
  return (color * variation).cwiseMax(0.0).cwiseMin(1.0);
}

double shading(const Eigen::Vector3d& normal) {
  // Light from above and from one side: the six axis directions get six distinct levels.
  static const Eigen::Vector3d light = Eigen::Vector3d(0.35, 0.55, 0.76).normalized();
  constexpr double ambient = 0.55;
  return ambient + (1.0 - ambient) * std::max(0.0, normal.dot(light));
}

}  // namespace kartograf::synth
