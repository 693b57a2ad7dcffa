#pragma once
// Reproducible random numbers (the synthetic world, procedural textures). std:: distributions are implementation-
// defined (the same seed gives different numbers with another standard library), so the
// conversions from raw 64-bit words to uniform / normal numbers are our own.
//
// Two generators: Rng, a sequential std::mt19937_64 stream for building a world; and
// counter-based hashing (hash_uniform, hash_normal) for per-pixel sensor noise, where the number
// for (frame seed, pixel, purpose) must not depend on the order in which pixels are processed, so
// that frames render identically on any number of threads.
#include <cmath>
#include <cstdint>
#include <random>

namespace kartograf {

// SplitMix64's finaliser: a bijective 64-bit mix with good avalanche.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A well-mixed 64-bit key for a tuple of integers (seed, index, stream, ...).
constexpr std::uint64_t hash_key(std::uint64_t a, std::uint64_t b, std::uint64_t c = 0) {
  return mix64(mix64(mix64(a) ^ b) ^ c);
}

// [0, 1) with 53 random bits.
constexpr double unit_interval(std::uint64_t bits) {
  return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

// The standard normal quantile (inverse CDF) by P. J. Acklam's rational approximation (relative
// error ~1e-9 in x): cheaper than Box-Muller (a logarithm only in the 5 % tails), and one 64-bit
// word gives one normal number.
inline double inverse_normal_cdf(double p) {
  constexpr double a[6] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                           1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  constexpr double b[5] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                           6.680131188771972e+01, -1.328068155288572e+01};
  constexpr double c[6] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                           -2.549671010233180e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  constexpr double d[4] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                           3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  auto tail = [&](double q) {
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  };
  if (p < kLow) return tail(std::sqrt(-2.0 * std::log(p)));
  if (p > 1.0 - kLow) return -tail(std::sqrt(-2.0 * std::log(1.0 - p)));
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

// A standard normal number from 64 random bits (53 of them, mapped into the open interval (0, 1)).
inline double standard_normal(std::uint64_t bits) {
  return inverse_normal_cdf((static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53);
}

// Counter-based draws: the same (key, stream) always gives the same number.
inline std::uint64_t hash_bits(std::uint64_t key, std::uint64_t stream) {
  return mix64(key ^ mix64(stream));
}
inline double hash_uniform(std::uint64_t key, std::uint64_t stream) {
  return unit_interval(hash_bits(key, stream));
}
inline double hash_normal(std::uint64_t key, std::uint64_t stream) {
  return standard_normal(hash_bits(key, stream));
}
// A cheap near-normal from the low 21 bits of `bits`: the sum of three 7-bit uniforms (Irwin-Hall),
// scaled to unit variance, bounded by +-3: for colour noise, where the tails do not matter.
inline double approx_normal_21(std::uint64_t bits) {
  const auto sum = (bits & 0x7f) + ((bits >> 7) & 0x7f) + ((bits >> 14) & 0x7f);
  // Each 7-bit uniform has mean 63.5 and variance (128^2 - 1) / 12.
  return (static_cast<double>(sum) - 190.5) / 63.998046845;
}

// A sequential stream (std::mt19937_64 is fully specified by the standard).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  std::uint64_t bits() { return engine_(); }
  double uniform() { return unit_interval(engine_()); }
  double uniform(double low, double high) { return low + (high - low) * uniform(); }
  // An integer in [low, high] (inclusive); the tiny modulo bias of 64-bit words is irrelevant here.
  int uniform_int(int low, int high) {
    const auto span = static_cast<std::uint64_t>(static_cast<std::int64_t>(high) - low + 1);
    return low + static_cast<int>(engine_() % span);
  }
  bool bernoulli(double p) { return uniform() < p; }
  double normal(double mean, double sigma) { return mean + sigma * standard_normal(engine_()); }
  // A derived, independent stream (e.g. one per room) so that adding draws to one part of the
  // generator does not shift every number after it.
  Rng fork(std::uint64_t salt) { return Rng(hash_key(engine_(), salt)); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace kartograf
