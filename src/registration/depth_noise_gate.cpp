#include "kartograf/registration/depth_noise_gate.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "kartograf/core/error.hpp"

namespace kartograf::registration {

void DepthNoiseGateParams::validate() const {
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  require(non_negative(sigmas) && non_negative(a) && non_negative(b) && std::isfinite(c),
          "odometry: depth_noise_gate: sigmas, a and b must be finite and >= 0, c finite");
  require(stride >= 1,
          "odometry: depth_noise_gate: stride must be >= 1, got " + std::to_string(stride));
}

double median_depth_m(const DepthImage& depth, double units_per_metre, int stride) {
  std::vector<std::uint16_t> samples;
  const std::span<const std::uint16_t> pixels = depth.pixels();
  samples.reserve(pixels.size() / static_cast<std::size_t>(stride) + 1);
  for (std::size_t i = 0; i < pixels.size(); i += static_cast<std::size_t>(stride)) {
    if (pixels[i] > 0) samples.push_back(pixels[i]);
  }
  if (samples.empty()) return 0;
  const auto middle = samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2);
  std::nth_element(samples.begin(), middle, samples.end());
  return *middle / units_per_metre;
}

double depth_noise_gate(double fixed_gate_m, double median_depth_m,
                        const DepthNoiseGateParams& params) {
  if (!(median_depth_m > 0)) return fixed_gate_m;
  return std::max(fixed_gate_m, params.sigmas * params.sigma_at(median_depth_m));
}

}  // namespace kartograf::registration
