#include "kartograf/semantic/normals_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/geometry/normals.hpp"

namespace kartograf::semantic {
namespace {

std::uint8_t to_level(double unit) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(unit * 255.0), 0L, 255L));
}

}  // namespace

double RangeNoiseProfile::at(double range) const {
  if (sigma.empty()) return 0.0;
  const auto bin = static_cast<std::size_t>(
      std::clamp(std::floor(range / bin_width), 0.0, static_cast<double>(sigma.size() - 1)));
  return sigma[bin];
}

RangeNoiseProfile estimate_range_noise(const PointImage& points, double bin_width,
                                       int min_samples) {
  require(bin_width > 0 && min_samples >= 1,
          "estimate_range_noise: bin_width must be > 0 and min_samples >= 1");
  const int w = points.width(), h = points.height();
  std::vector<std::vector<float>> samples;
  auto range_at = [&](int x, int y) {
    const Point4f& p = points(x, y);
    return is_valid(p) ? p.head<3>().norm() : -1.0f;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float r = range_at(x, y);
      if (r <= 0) continue;
      const auto bin = static_cast<std::size_t>(r / bin_width);
      if (bin >= samples.size()) samples.resize(bin + 1);
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (x - dx < 0 || y - dy < 0 || x + dx >= w || y + dy >= h) continue;
        const float before = range_at(x - dx, y - dy), after = range_at(x + dx, y + dy);
        if (before > 0 && after > 0) samples[bin].push_back(std::fabs(before - 2 * r + after));
      }
    }
  }
  RangeNoiseProfile profile;
  profile.bin_width = bin_width;
  std::vector<double> sigma(samples.size(), -1.0);
  for (std::size_t b = 0; b < samples.size(); ++b) {
    auto& v = samples[b];
    if (static_cast<int>(v.size()) < min_samples) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    sigma[b] = 1.4826 * v[v.size() / 2] / std::sqrt(6.0);
  }
  if (std::none_of(sigma.begin(), sigma.end(), [](double s) { return s >= 0; })) return profile;
  profile.sigma = sigma;
  for (std::size_t b = 0; b < sigma.size(); ++b) {
    if (sigma[b] >= 0) continue;
    for (std::size_t d = 1;; ++d) {  // nearest populated bin, the lower one on a tie
      if (b >= d && sigma[b - d] >= 0) {
        profile.sigma[b] = sigma[b - d];
        break;
      }
      if (b + d < sigma.size() && sigma[b + d] >= 0) {
        profile.sigma[b] = sigma[b + d];
        break;
      }
    }
  }
  return profile;
}

PointImage smooth_organized_points(const PointImage& points, const NormalsImageParams& params) {
  const bool measure = params.noise_sigmas > 0 && params.smoothing_radius > 0;
  return smooth_organized_points(points, params,
                                 measure ? estimate_range_noise(points) : RangeNoiseProfile{});
}

PointImage smooth_organized_points(const PointImage& points, const NormalsImageParams& params,
                                   const RangeNoiseProfile& noise) {
  require(params.smoothing_radius >= 0,
          "smooth_organized_points: smoothing_radius must be >= 0, got " +
              std::to_string(params.smoothing_radius));
  require(std::isfinite(params.max_relative_range_jump) && params.max_relative_range_jump > 0,
          "smooth_organized_points: max_relative_range_jump must be positive");
  require(std::isfinite(params.noise_sigmas) && params.noise_sigmas >= 0,
          "smooth_organized_points: noise_sigmas must be >= 0");
  const int w = points.width(), h = points.height(), r = params.smoothing_radius;
  PointImage smoothed(w, h, invalid_point());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Point4f& centre = points(x, y);
      if (!is_valid(centre)) continue;
      const float range = centre.head<3>().norm();
      const float limit = std::max(params.max_relative_range_jump * range,
                                   params.noise_sigmas * static_cast<float>(noise.at(range)));
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int count = 0;
      for (int dy = std::max(-r, -y); dy <= std::min(r, h - 1 - y); ++dy) {
        for (int dx = std::max(-r, -x); dx <= std::min(r, w - 1 - x); ++dx) {
          const Point4f& q = points(x + dx, y + dy);
          if (!is_valid(q) || std::fabs(q.head<3>().norm() - range) > limit) continue;
          sum += q.head<3>().cast<double>();
          ++count;
        }
      }
      const Eigen::Vector3f mean = (sum / count).cast<float>();
      smoothed(x, y) = Point4f(mean.x(), mean.y(), mean.z(), 1.0f);
    }
  }
  return smoothed;
}

NormalImage estimate_organized_normals(const compute::Context& context, const PointImage& points,
                                       const NormalsImageParams& params) {
  PointImage shifted =
      params.smoothing_radius > 0 ? smooth_organized_points(points, params) : points;
  float min_z = std::numeric_limits<float>::infinity();
  for (const Point4f& p : shifted.pixels()) {
    if (is_valid(p)) min_z = std::min(min_z, p.z());
  }
  if (!std::isfinite(min_z)) return NormalImage(points.width(), points.height(), invalid_point());
  const float shift = std::max(0.0f, 1.0f - min_z);
  for (Point4f& p : shifted.pixels()) {
    if (is_valid(p)) p.z() += shift;
  }
  // z >= 1 everywhere, so this threshold admits any neighbour: the depth-jump test is off.
  geometry::NormalParams normal_params;
  normal_params.max_depth_jump = 1e30f;
  NormalImage normals = geometry::estimate_normals(context, shifted, normal_params);
  for (std::size_t i = 0; i < normals.size(); ++i) {
    Point4f& n = normals.pixels()[i];
    const Point4f& p = points.pixels()[i];
    if (!is_valid(n)) continue;
    if (!is_valid(p)) {
      n = invalid_point();
    } else if (n.head<3>().dot(p.head<3>()) > 0) {
      n.head<3>() = -n.head<3>();
    }
  }
  return normals;
}

RgbImage normals_to_rgb(const NormalImage& normals, NormalEncoding encoding) {
  RgbImage rgb(normals.width(), normals.height(), Rgb8{0, 0, 0});
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const Point4f& n = normals.pixels()[i];
    if (!is_valid(n)) continue;
    Rgb8& c = rgb.pixels()[i];
    for (int k = 0; k < 3; ++k) {
      c[k] = encoding == NormalEncoding::absolute ? to_level(std::fabs(n[k]))
                                                  : to_level((n[k] + 1.0) / 2.0);
    }
  }
  return rgb;
}

GrayImage normals_rgb_to_gray(const RgbImage& normals_rgb) {
  GrayImage gray(normals_rgb.width(), normals_rgb.height());
  for (std::size_t i = 0; i < gray.size(); ++i) {
    const Rgb8& c = normals_rgb.pixels()[i];
    gray.pixels()[i] = to_level((0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]) / 255.0);
  }
  return gray;
}

}  // namespace kartograf::semantic
