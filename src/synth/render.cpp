#include "kartograf/synth/render.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "kartograf/core/error.hpp"
#include "kartograf/core/random.hpp"
#include "kartograf/synth/ray_caster.hpp"
#include "parallel.hpp"
#include "plane_rasterizer.hpp"

namespace kartograf::synth {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// Noise streams: independent draws for one pixel.
enum Stream : std::uint64_t {
  kColor = 1,
  kLateralU,
  kLateralV,
  kAxial,
  kFlying,
  kFlyingMix,
  kGrazing,
  kDark
};

// sRGB-like transfer (gamma 2.2) from linear [0, 1] to 8-bit, tabulated.
class GammaTable {
 public:
  GammaTable() {
    for (int i = 0; i < kSize; ++i) {
      table_[i] = 255.0 * std::pow(static_cast<double>(i) / (kSize - 1), 1.0 / 2.2);
    }
  }
  double operator()(double linear) const {
    const double x = std::clamp(linear, 0.0, 1.0) * (kSize - 1);
    const int i = std::min(kSize - 2, static_cast<int>(x));
    return table_[i] + (table_[i + 1] - table_[i]) * (x - i);
  }

 private:
  static constexpr int kSize = 1024;
  std::array<double, kSize> table_{};
};

std::uint8_t to_byte(double value) {
  return static_cast<std::uint8_t>(std::clamp(value, 0.0, 255.0) + 0.5);
}

// acos on [0, 1] through a table over sqrt(1 - c), in which acos is smooth (acos(c) ~ sqrt(2 (1 -
// c)) near 1): ~1e-6 rad accurate and several times cheaper than std::acos, which the noise model
// would otherwise call for every pixel.
class AcosTable {
 public:
  AcosTable() {
    for (int i = 0; i < kSize; ++i) {
      const double x = static_cast<double>(i) / (kSize - 1);
      table_[i] = std::acos(1.0 - x * x);
    }
  }
  double operator()(double c) const {
    const double x = std::sqrt(std::clamp(1.0 - c, 0.0, 1.0)) * (kSize - 1);
    const int i = std::min(kSize - 2, static_cast<int>(x));
    return table_[i] + (table_[i + 1] - table_[i]) * (x - i);
  }

 private:
  static constexpr int kSize = 2048;
  std::array<double, kSize> table_{};
};

double incidence_angle(double cos_incidence) {
  static const AcosTable table;
  return table(cos_incidence);
}

struct PixelState {
  float cos_incidence = 0;  // |cos| of the angle between the ray and the surface normal
  float albedo = 0;         // luminance
  bool row_run = false;     // the same plane kMaxShift pixels left and right
};

constexpr int kMaxShift = 3;  // lateral displacement limit [px]

Face face_of(const Eigen::Vector3d& normal) {
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  return make_face(axis, normal[axis] > 0);
}

class FrameRenderer {
 public:
  FrameRenderer(const World& world, const PinholeIntrinsics& k, const Eigen::Isometry3d& pose,
                const NoiseModel& noise, std::uint64_t seed)
      : world_(world),
        rasterizer_(world, k, pose),
        k_(k),
        rotation_(pose.linear()),
        origin_(pose.translation()),
        noise_(noise),
        seed_mixed_(mix64(seed)) {
    for (int f = 0; f < kFaceCount; ++f) shade_[f] = shading(face_normal(static_cast<Face>(f)));
    const int w = k.width, h = k.height;
    frame_.color = RgbImage(w, h, Rgb8{0, 0, 0});
    frame_.depth = DepthImage(w, h, 0);
    frame_.plane_id = LabelImage(w, h, kUnlabeled);
    frame_.semantic = SemanticImage(w, h, SemanticClass::unknown);
    frame_.depth_metres = Image<float>(w, h, std::numeric_limits<float>::quiet_NaN());
    state_.assign(static_cast<std::size_t>(w) * h, PixelState{});
    depth_.assign(static_cast<std::size_t>(w) * h, 0.0);
    ids_.assign(static_cast<std::size_t>(w) * h, kUnlabeled);
  }

  SyntheticFrame run(int threads) {
    detail::parallel_rows(k_.height, threads, [&](int begin, int end) { trace_rows(begin, end); });
    if (noise_.lateral) {
      detail::parallel_rows(k_.height, threads,
                            [&](int begin, int end) { mark_row_runs(begin, end); });
    }
    detail::parallel_rows(k_.height, threads,
                          [&](int begin, int end) { measure_rows(begin, end); });
    return std::move(frame_);
  }

 private:
  Eigen::Vector3d ray(double u, double v) const {
    return rotation_ * Eigen::Vector3d((u - k_.cx) / k_.fx, (v - k_.cy) / k_.fy, 1.0);
  }
  std::uint64_t pixel_key(int u, int v) const {
    return mix64(seed_mixed_ ^
                 (static_cast<std::uint64_t>(v) * static_cast<std::uint64_t>(k_.width) +
                  static_cast<std::uint64_t>(u)));
  }

  // Pass 1: the exact visible surface of every pixel (ground truth) and its colour.
  void trace_rows(int begin, int end) {
    static const GammaTable gamma;
    rasterizer_.rasterize(begin, end, depth_, ids_);
    for (int v = begin; v < end; ++v) {
      for (int u = 0; u < k_.width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * k_.width + u;
        if (ids_[i] == kUnlabeled) continue;
        const Plane& plane = world_.plane(ids_[i]);
        const Eigen::Vector3d d = ray(u, v);
        SurfaceHit hit;
        hit.t = depth_[i];
        hit.point = origin_ + hit.t * d;
        hit.face = face_of(plane.normal);
        hit.plane = plane.id;
        hit.material =
            plane.material >= 0 ? plane.material : world_.floor_material_at(hit.point.head<2>());
        PixelState& s = state_[i];
        s.cos_incidence = static_cast<float>(std::fabs(plane.normal.dot(d)) / d.norm());
        frame_.depth_metres(u, v) = static_cast<float>(hit.t);
        frame_.plane_id(u, v) = hit.plane;
        frame_.semantic(u, v) = plane.semantic;

        const Eigen::Vector3d albedo = surface_albedo(world_, hit);
        s.albedo = static_cast<float>(luminance(albedo));
        const Eigen::Vector3d linear = albedo * shade_[static_cast<int>(hit.face)];
        // Colour noise: one 64-bit draw, 21 bits per channel.
        const std::uint64_t bits = noise_.color_noise ? hash_bits(pixel_key(u, v), kColor) : 0;
        Rgb8& out = frame_.color(u, v);
        for (int c = 0; c < 3; ++c) {
          double value = gamma(linear[c]);
          if (noise_.color_noise) value += noise_.color_sigma * approx_normal_21(bits >> (21 * c));
          out[c] = to_byte(value);
        }
      }
    }
  }

  float true_depth(int u, int v) const {
    if (u < 0 || v < 0 || u >= k_.width || v >= k_.height)
      return std::numeric_limits<float>::quiet_NaN();
    return frame_.depth_metres(u, v);
  }

  // The largest depth jump to a 4-neighbour, as (foreground, background), if above the threshold.
  bool depth_edge(int u, int v, double z, double& fore, double& back) const {
    double jump = noise_.flying_min_jump;
    bool found = false;
    const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
    for (int i = 0; i < 4; ++i) {
      const double zn = true_depth(u + du[i], v + dv[i]);
      if (std::isnan(zn) || std::fabs(zn - z) <= jump) continue;
      jump = std::fabs(zn - z);
      fore = std::min(z, zn);
      back = std::max(z, zn);
      found = true;
    }
    return found;
  }

  // Pixels whose row has the same plane kMaxShift pixels to both sides (or to the border).
  void mark_row_runs(int begin, int end) {
    for (int v = begin; v < end; ++v) {
      for (int u = 0; u < k_.width; ++u) {
        bool same = true;
        const Label id = frame_.plane_id(u, v);
        for (int x = std::max(0, u - kMaxShift); x <= std::min(k_.width - 1, u + kMaxShift) && same;
             ++x) {
          same = frame_.plane_id(x, v) == id;
        }
        state_[static_cast<std::size_t>(v) * k_.width + u].row_run = same;
      }
    }
  }

  // Whether every pixel within kMaxShift (Chebyshev) sees the same plane: then lateral noise
  // changes nothing there and need not be drawn.
  bool inside_plane(int u, int v) const {
    const Label id = frame_.plane_id(u, v);
    for (int y = std::max(0, v - kMaxShift); y <= std::min(k_.height - 1, v + kMaxShift); ++y) {
      const std::size_t i = static_cast<std::size_t>(y) * k_.width + u;
      if (!state_[i].row_run || frame_.plane_id(u, y) != id) return false;
    }
    return true;
  }

  // Lateral noise moves depth edges: the pixel measures along its own ray, but the surface it
  // sees is that of the pixel (du, dv) away (rounded): the same depth inside a plane, the
  // neighbouring surface's plane near an edge. False: that pixel sees nothing.
  bool displaced_depth(int u, int v, double du, double dv, double& z, double& cos_incidence) const {
    auto shift = [](double d) {
      return std::clamp(static_cast<int>(std::lround(d)), -kMaxShift, kMaxShift);
    };
    const int x = std::clamp(u + shift(du), 0, k_.width - 1);
    const int y = std::clamp(v + shift(dv), 0, k_.height - 1);
    const Label other = frame_.plane_id(x, y);
    if (other == frame_.plane_id(u, v)) return true;  // same surface: nothing changes
    if (std::isnan(frame_.depth_metres(x, y))) return false;
    z = frame_.depth_metres(x, y);
    cos_incidence = state_[static_cast<std::size_t>(y) * k_.width + x].cos_incidence;
    if (other == 0) return true;
    // Where this pixel's ray meets the other surface's plane, if that is near the other depth.
    const Plane& plane = world_.plane(other);
    const Eigen::Vector3d d = ray(u, v);
    const double denom = plane.normal.dot(d);
    if (std::fabs(denom) > 1e-12) {
      const double t = -(plane.normal.dot(origin_) + plane.offset) / denom;
      if (t > 0.5 * z && t < 2.0 * z) z = t;
    }
    return true;
  }

  // Pass 2: the sensor's depth.
  void measure_rows(int begin, int end) {
    for (int v = begin; v < end; ++v) {
      for (int u = 0; u < k_.width; ++u) {
        const double z_true = frame_.depth_metres(u, v);
        if (std::isnan(z_true)) continue;
        const PixelState& s = state_[static_cast<std::size_t>(v) * k_.width + u];
        const std::uint64_t key = pixel_key(u, v);
        double z = z_true;
        double cos_incidence = s.cos_incidence;
        double theta = incidence_angle(cos_incidence);
        double fore = 0, back = 0;
        if (noise_.flying_pixels && depth_edge(u, v, z_true, fore, back) &&
            hash_uniform(key, kFlying) < noise_.flying_fraction) {
          z = fore + hash_uniform(key, kFlyingMix) * (back - fore);
        } else if (noise_.lateral && !inside_plane(u, v)) {
          const double capped = std::min(theta, 85.0 * kDegree);
          const double sigma =
              noise_.lateral_px + 0.035 * capped / (0.5 * std::numbers::pi - capped);
          const double du = sigma * hash_normal(key, kLateralU),
                       dv = sigma * hash_normal(key, kLateralV);
          const double before = cos_incidence;
          if (!displaced_depth(u, v, du, dv, z, cos_incidence)) continue;
          if (cos_incidence != before) theta = incidence_angle(cos_incidence);
        }
        if (noise_.axial) z += noise_.axial_sigma(z, theta) * hash_normal(key, kAxial);
        if (noise_.quantization) {
          const double fb = k_.fx * noise_.baseline;
          const double disparity = std::floor(fb / z * noise_.subpixel + 0.5) / noise_.subpixel;
          if (!(disparity > 0)) continue;
          z = fb / disparity;
        }
        if (!(z >= noise_.min_range && z <= noise_.max_range)) continue;
        if (noise_.grazing_dropout) {
          const double angle = theta / kDegree;
          const double span = noise_.grazing_limit_deg - noise_.grazing_start_deg;
          const double p = span > 0 ? (angle - noise_.grazing_start_deg) / span
                                    : (angle >= noise_.grazing_limit_deg ? 1.0 : 0.0);
          if (p > 0 && hash_uniform(key, kGrazing) < p) continue;
        }
        if (noise_.dark_dropout && s.albedo < noise_.dark_albedo &&
            hash_uniform(key, kDark) < 1.0 - s.albedo / noise_.dark_albedo) {
          continue;
        }
        const double units = std::floor(z * kTumDepthUnitsPerMetre + 0.5);
        if (units >= 1 && units <= 65535) frame_.depth(u, v) = static_cast<std::uint16_t>(units);
      }
    }
  }

  const World& world_;
  const detail::PlaneRasterizer rasterizer_;
  const PinholeIntrinsics k_;
  const Eigen::Matrix3d rotation_;
  const Eigen::Vector3d origin_;
  const NoiseModel noise_;
  const std::uint64_t seed_mixed_;
  double shade_[kFaceCount] = {};
  SyntheticFrame frame_;
  std::vector<PixelState> state_;
  std::vector<double> depth_;  // exact ray parameter (= z) per pixel
  std::vector<Label> ids_;
};

}  // namespace

NoiseModel NoiseModel::none() {
  NoiseModel m;
  m.axial = m.lateral = m.quantization = false;
  m.grazing_dropout = m.dark_dropout = m.flying_pixels = m.color_noise = false;
  m.min_range = 0;
  m.max_range = std::numeric_limits<double>::infinity();
  return m;
}

double NoiseModel::axial_sigma(double z, double theta) const {
  double sigma = axial_a + axial_b * (z - axial_c) * (z - axial_c);
  if (axial_angle_term) {
    const double t = std::min(theta, 85.0 * kDegree);
    const double r = t / (0.5 * std::numbers::pi - t);
    sigma += 0.0001 / std::sqrt(std::max(z, 1e-3)) * r * r;
  }
  return sigma;
}

void NoiseModel::validate() const {
  auto check = [](bool ok, const std::string& what) { require(ok, "NoiseModel: " + what); };
  check(axial_a >= 0 && axial_b >= 0 && std::isfinite(axial_c), "axial coefficients must be >= 0");
  check(lateral_px >= 0 && std::isfinite(lateral_px), "lateral_px must be >= 0");
  check(!quantization || (baseline > 0 && subpixel >= 1),
        "quantization needs baseline > 0 and subpixel >= 1");
  check(min_range >= 0 && max_range > min_range, "ranges must satisfy 0 <= min_range < max_range");
  check(grazing_start_deg <= grazing_limit_deg && grazing_limit_deg <= 90,
        "grazing angles must satisfy start <= limit <= 90");
  check(dark_albedo > 0 && dark_albedo <= 1, "dark_albedo must be in (0, 1]");
  check(flying_fraction >= 0 && flying_fraction <= 1 && flying_min_jump > 0,
        "flying_fraction must be in [0, 1] and flying_min_jump > 0");
  check(color_sigma >= 0 && std::isfinite(color_sigma), "color_sigma must be >= 0");
}

SyntheticFrame render(const World& world, const PinholeIntrinsics& intrinsics,
                      const Eigen::Isometry3d& camera_to_world, const NoiseModel& noise,
                      std::uint64_t frame_seed, const RenderParams& options) {
  intrinsics.validate("render");
  noise.validate();
  return FrameRenderer(world, intrinsics, camera_to_world, noise, frame_seed).run(options.threads);
}

}  // namespace kartograf::synth
