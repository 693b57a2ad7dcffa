#pragma once
// Procedural surface materials: an albedo texture fixed to the surface (so colour-assisted ICP
// sees the same gradients from every view) and the view-independent shading of the renderer.
#include <cstdint>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace kartograf::synth {

enum class Pattern : std::uint8_t {
  solid,    // color_a, with value-noise variation of noise_amplitude
  noise,    // value noise between color_a and color_b (paint, plaster, fabric)
  stripes,  // bands of period `period` along u (wallpaper)
  checker,  // square tiles of side `period` with dark grout lines (floor tiles)
  wood,     // noisy bands along u (wood grain)
};

std::string_view to_string(Pattern pattern);

struct Material {
  std::string name;
  Pattern pattern = Pattern::solid;
  Eigen::Vector3d color_a = Eigen::Vector3d::Constant(0.7);  // linear albedo, 0..1 per channel
  Eigen::Vector3d color_b = Eigen::Vector3d::Constant(0.5);
  double period = 0.5;            // metres: stripe / tile / grain spacing
  double noise_amplitude = 0.08;  // relative brightness variation
  double noise_scale = 0.15;      // metres: size of the value-noise features
  std::uint64_t seed = 0;         // decorrelates the noise of otherwise equal materials

  // Albedo at surface coordinates (u, v) in metres (the two world axes spanning the face).
  Eigen::Vector3d albedo(double u, double v) const;
};

// Rec. 709 luma of a linear albedo: what decides whether the IR sensor gets a return.
inline double luminance(const Eigen::Vector3d& albedo) {
  return 0.2126 * albedo.x() + 0.7152 * albedo.y() + 0.0722 * albedo.z();
}

// Lambertian shading factor for a fixed light direction plus ambient light. It depends on the
// surface normal only, so a surface has the same brightness from every view.
double shading(const Eigen::Vector3d& normal);

// 2-D value noise in [0, 1]: a hashed lattice with smooth interpolation, two octaves.
double value_noise(double u, double v, std::uint64_t seed);

}  // namespace kartograf::synth
