#include "kartograf/registration/photometric_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "kartograf/core/error.hpp"

namespace kartograf::registration {

namespace {

using GreyImage = Image<float>;

GreyImage grey_of(const RgbImage& color) {
  GreyImage grey(color.width(), color.height());
  const auto in = color.pixels();
  const auto out = grey.pixels();
  for (std::size_t i = 0; i < in.size(); ++i) {
    out[i] = (static_cast<float>(in[i][0]) + static_cast<float>(in[i][1]) +
              static_cast<float>(in[i][2])) /
             3.0f;
  }
  return grey;
}

// One pass of the separable binomial filter [1 4 6 4 1] / 16, borders clamped.
void blur(GreyImage& image) {
  const int w = image.width(), h = image.height();
  const float k[5] = {1 / 16.0f, 4 / 16.0f, 6 / 16.0f, 4 / 16.0f, 1 / 16.0f};
  GreyImage tmp(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      for (int d = -2; d <= 2; ++d) sum += k[d + 2] * image(std::clamp(x + d, 0, w - 1), y);
      tmp(x, y) = sum;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      for (int d = -2; d <= 2; ++d) sum += k[d + 2] * tmp(x, std::clamp(y + d, 0, h - 1));
      image(x, y) = sum;
    }
  }
}

GreyImage blurred(const GreyImage& grey, int passes) {
  GreyImage result = grey;
  for (int i = 0; i < passes; ++i) blur(result);
  return result;
}

// An image with its central-difference gradients, sampled bilinearly.
struct Textured {
  GreyImage value, dx, dy;

  explicit Textured(GreyImage image) : value(std::move(image)) {
    const int w = value.width(), h = value.height();
    dx = GreyImage(w, h, 0.0f);
    dy = GreyImage(w, h, 0.0f);
    for (int y = 1; y + 1 < h; ++y) {
      for (int x = 1; x + 1 < w; ++x) {
        dx(x, y) = 0.5f * (value(x + 1, y) - value(x - 1, y));
        dy(x, y) = 0.5f * (value(x, y + 1) - value(x, y - 1));
      }
    }
  }
  // False outside the area where all three are defined.
  bool sample(double u, double v, double& i, double& gx, double& gy) const {
    if (!(u >= 1 && v >= 1 && u < value.width() - 2 && v < value.height() - 2)) return false;
    const int x = static_cast<int>(u), y = static_cast<int>(v);
    const double fx = u - x, fy = v - y;
    const auto lerp = [&](const GreyImage& image) {
      return (1 - fy) * ((1 - fx) * image(x, y) + fx * image(x + 1, y)) +
             fy * ((1 - fx) * image(x, y + 1) + fx * image(x + 1, y + 1));
    };
    i = lerp(value);
    gx = lerp(dx);
    gy = lerp(dy);
    return true;
  }
};

struct Sample {
  Eigen::Vector3d point;  // source camera frame
  double intensity = 0;
};

// Robust Gauss-Newton sums of all residuals at `motion`.
struct Sums {
  Eigen::MatrixXd jtj;
  Eigen::VectorXd jtr;
  double cost = 0;
  double squared = 0;
  std::size_t count = 0;
};

Sums evaluate(const std::vector<Sample>& samples, const Textured& target,
              const PinholeIntrinsics& k, const Eigen::Isometry3d& motion,
              std::span<const se3::Vector6d> directions, double huber) {
  const auto n = static_cast<Eigen::Index>(directions.size());
  Sums sums{Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n), 0, 0, 0};
  const Eigen::Matrix3d rotation = motion.linear();
  Eigen::VectorXd j(n);
  for (const Sample& sample : samples) {
    const Eigen::Vector3d q = motion * sample.point;
    if (q.z() <= 0) continue;
    const double u = k.fx * q.x() / q.z() + k.cx, v = k.fy * q.y() / q.z() + k.cy;
    double intensity, gx, gy;
    if (!target.sample(u, v, intensity, gx, gy)) continue;
    const double r = intensity - sample.intensity;
    // d(u, v)/dq, then dq/ds_k = R (omega_k x p + v_k).
    const Eigen::RowVector3d du(k.fx / q.z(), 0, -k.fx * q.x() / (q.z() * q.z()));
    const Eigen::RowVector3d dv(0, k.fy / q.z(), -k.fy * q.y() / (q.z() * q.z()));
    const Eigen::RowVector3d dr = gx * du + gy * dv;
    for (Eigen::Index d = 0; d < n; ++d) {
      const se3::Vector6d& dir = directions[static_cast<std::size_t>(d)];
      j(d) = dr * (rotation * (dir.head<3>().cross(sample.point) + dir.tail<3>()));
    }
    const double a = std::abs(r);
    const double weight = a <= huber ? 1.0 : huber / a;
    sums.cost += a <= huber ? 0.5 * r * r : huber * (a - 0.5 * huber);
    sums.jtj.noalias() += weight * j * j.transpose();
    sums.jtr.noalias() += weight * r * j;
    sums.squared += r * r;
    ++sums.count;
  }
  return sums;
}

Eigen::Isometry3d step(const Eigen::Isometry3d& motion, std::span<const se3::Vector6d> directions,
                       const Eigen::VectorXd& amounts) {
  se3::Vector6d xi = se3::Vector6d::Zero();
  for (std::size_t d = 0; d < directions.size(); ++d) {
    xi += amounts(static_cast<Eigen::Index>(d)) * directions[d];
  }
  return motion * se3::exp(xi);
}

using Mask = Image<std::uint8_t>;

// Depth steps between neighbouring pixels larger than this are surfaces apart, not one surface
// seen at a grazing angle (a floor 4 m away steps about 3 cm a pixel at 640x480).
constexpr double kEdgeJumpFraction = 0.03;
constexpr double kEdgeJumpMetres = 0.01;

// Set wherever a set pixel lies within `radius` (a square window), in two separable passes.
Mask dilated(const Mask& mask, int radius) {
  const int w = mask.width(), h = mask.height();
  const auto pass = [&](const Mask& in, bool along_rows) {
    Mask out(w, h, 0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (!in(x, y)) continue;
        for (int d = -radius; d <= radius; ++d) {
          const int u = along_rows ? x + d : x, v = along_rows ? y : y + d;
          if (u >= 0 && u < w && v >= 0 && v < h) out(u, v) = 1;
        }
      }
    }
    return out;
  };
  return pass(pass(mask, true), false);
}

// Source pixels whose smoothed grey level mixes two surfaces apart in depth (a cabinet's edge
// against the wall behind it): as the camera moves the two slide apart, so their residuals pull
// the motion towards the parallax rather than the camera's motion. Only steps between pixels that
// both have depth count: a dark surface's dropouts or a range limit say nothing of depth. Their
// reach is the fine pass's (one binomial pass, 2 pixels, and the gradient's 1). The coarse pass
// keeps them, as its wide basin needs the edges' contrast, and the fine pass removes what they
// pull: masked to the coarse blur's reach of 6 pixels, survey seed 8's degenerate views kept too
// few textured pixels to refine; masked to 3 in both passes, seeds 5, 6 and 10 drifted more.
Mask near_depth_edges(const DepthImage& depth, double units_per_metre) {
  const int w = depth.width(), h = depth.height();
  Mask edge(w, h, 0);
  const auto apart = [&](int x0, int y0, int x1, int y1) {
    const double a = depth(x0, y0) / units_per_metre, b = depth(x1, y1) / units_per_metre;
    return depth(x0, y0) != 0 && depth(x1, y1) != 0 &&
           std::abs(a - b) > kEdgeJumpFraction * std::min(a, b) + kEdgeJumpMetres;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (x + 1 < w && apart(x, y, x + 1, y)) edge(x, y) = edge(x + 1, y) = 1;
      if (y + 1 < h && apart(x, y, x, y + 1)) edge(x, y) = edge(x, y + 1) = 1;
    }
  }
  constexpr int kFinePassReach = 3;
  return dilated(edge, kFinePassReach);
}

// The pixels the fine pass and intensity_rmse leave out: none unless params.mask_depth_edges.
Mask excluded_pixels(const DepthImage& depth, double units_per_metre,
                     const PhotometricParams& params) {
  if (!params.mask_depth_edges) return Mask(depth.width(), depth.height(), 0);
  return near_depth_edges(depth, units_per_metre);
}

std::vector<Sample> samples_of(const DepthImage& depth, const Textured& source,
                               const PinholeIntrinsics& k, double units_per_metre,
                               const PhotometricParams& params, const Mask& excluded) {
  std::vector<Sample> samples;
  const double min_squared = params.min_gradient * params.min_gradient;
  for (int y = 2; y + 2 < depth.height(); y += params.pixel_step) {
    for (int x = 2; x + 2 < depth.width(); x += params.pixel_step) {
      const double z = depth(x, y) / units_per_metre;
      if (depth(x, y) == 0 || z > params.max_depth || excluded(x, y)) continue;
      const double gx = source.dx(x, y), gy = source.dy(x, y);
      if (gx * gx + gy * gy < min_squared) continue;
      samples.push_back(
          {Eigen::Vector3d((x - k.cx) * z / k.fx, (y - k.cy) * z / k.fy, z), source.value(x, y)});
    }
  }
  return samples;
}

// PhotometricResult::sigma_m of the last sums: the images' own uncertainty in the first
// `measured` directions, the others held where they are (by the start's information).
double motion_sigma(const Sums& sums, std::span<const se3::Vector6d> directions,
                    std::size_t measured) {
  measured = std::min(measured, directions.size());
  if (sums.count <= directions.size()) return std::numeric_limits<double>::infinity();
  const double variance = sums.squared / static_cast<double>(sums.count - directions.size());
  const auto m = static_cast<Eigen::Index>(measured);
  const Eigen::MatrixXd block = sums.jtj.topLeftCorner(m, m);
  const Eigen::MatrixXd covariance = variance * block.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
  double sigma = 0;
  for (std::size_t d = 0; d < measured; ++d) {
    const auto k = static_cast<Eigen::Index>(d);
    // A point 2 m ahead moves by |v| + 2 |omega| at most per unit of this direction.
    const double size = directions[d].tail<3>().norm() + 2.0 * directions[d].head<3>().norm();
    sigma = std::max(sigma, std::sqrt(std::max(0.0, covariance(k, k))) * size);
  }
  return std::isfinite(sigma) ? sigma : std::numeric_limits<double>::infinity();
}

// The start's own information on the amounts of the directions, in the photometric cost's units
// (grey levels^2): it holds the refinement to the start as far as the start was measured.
struct Prior {
  Eigen::MatrixXd information;
  Eigen::VectorXd amounts;  // moved so far, from the start

  Prior(const se3::Matrix6d& start_information, std::span<const se3::Vector6d> directions,
        double intensity_sigma) {
    const auto n = static_cast<Eigen::Index>(directions.size());
    Eigen::MatrixXd along(6, n);
    for (Eigen::Index k = 0; k < n; ++k) along.col(k) = directions[static_cast<std::size_t>(k)];
    information = intensity_sigma * intensity_sigma * along.transpose() * start_information * along;
    amounts = Eigen::VectorXd::Zero(n);
  }
  // Mean cost per residual, as the photometric cost is compared.
  double cost(const Eigen::VectorXd& a, std::size_t count) const {
    return count ? 0.5 * a.dot(information * a) / static_cast<double>(count) : 0.0;
  }
};

double mean_cost(const Sums& sums) {
  return sums.count ? sums.cost / static_cast<double>(sums.count) : 0.0;
}

// Robust Gauss-Newton from `motion` (updated), a step kept only if it lowers the mean cost.
Sums descend(const std::vector<Sample>& samples, const Textured& target, const PinholeIntrinsics& k,
             std::span<const se3::Vector6d> directions, const PhotometricParams& params,
             Eigen::Isometry3d& motion, Prior& prior) {
  Sums sums = evaluate(samples, target, k, motion, directions, params.huber_levels);
  for (int iteration = 0; iteration < params.iterations && sums.count >= params.min_pixels;
       ++iteration) {
    const Eigen::VectorXd delta =
        -(sums.jtj + prior.information).ldlt().solve(sums.jtr + prior.information * prior.amounts);
    if (!delta.allFinite()) break;
    const Eigen::Isometry3d candidate = step(motion, directions, delta);
    Sums next = evaluate(samples, target, k, candidate, directions, params.huber_levels);
    // Compare mean costs: a step may move residuals in or out of the image.
    if (next.count < params.min_pixels ||
        mean_cost(next) + prior.cost(prior.amounts + delta, next.count) >=
            mean_cost(sums) + prior.cost(prior.amounts, sums.count)) {
      break;
    }
    motion = candidate;
    prior.amounts += delta;
    sums = std::move(next);
  }
  return sums;
}

void require_camera_sized(const DepthImage& source_depth, const RgbImage& source_color,
                          const RgbImage& target_color, const PinholeIntrinsics& camera) {
  const auto same_size = [&](int w, int h) { return w == camera.width && h == camera.height; };
  require(same_size(source_depth.width(), source_depth.height()) &&
              same_size(source_color.width(), source_color.height()) &&
              same_size(target_color.width(), target_color.height()),
          "photometric refinement: depth and colour images must have the camera's size " +
              std::to_string(camera.width) + "x" + std::to_string(camera.height));
}

// A pair's images as intensity_rmse and intensity_disagreement compare motions on: one smoothing
// pass, the source's textured pixels (none where fewer than params.min_pixels).
struct ComparedPair {
  Textured target;
  std::vector<Sample> samples;
};

ComparedPair compared_pair(const DepthImage& source_depth, const RgbImage& source_color,
                           const RgbImage& target_color, const PinholeIntrinsics& camera,
                           double units_per_metre, const PhotometricParams& params) {
  require_camera_sized(source_depth, source_color, target_color, camera);
  const Textured source(blurred(grey_of(source_color), 1));
  const Mask excluded = excluded_pixels(source_depth, units_per_metre, params);
  ComparedPair pair{Textured(blurred(grey_of(target_color), 1)),
                    samples_of(source_depth, source, camera, units_per_metre, params, excluded)};
  if (pair.samples.size() < params.min_pixels) pair.samples.clear();
  return pair;
}

}  // namespace

std::vector<double> intensity_rmse(const DepthImage& source_depth, const RgbImage& source_color,
                                   const RgbImage& target_color, const PinholeIntrinsics& camera,
                                   double units_per_metre,
                                   std::span<const Eigen::Isometry3d> source_to_target,
                                   const PhotometricParams& params) {
  const ComparedPair pair =
      compared_pair(source_depth, source_color, target_color, camera, units_per_metre, params);
  std::vector<double> rmse(source_to_target.size(), 0.0);
  if (pair.samples.empty()) return rmse;
  for (std::size_t m = 0; m < source_to_target.size(); ++m) {
    const Sums sums =
        evaluate(pair.samples, pair.target, camera, source_to_target[m], {}, params.huber_levels);
    if (sums.count >= params.min_pixels) rmse[m] = std::sqrt(sums.squared / sums.count);
  }
  return rmse;
}

std::vector<double> intensity_disagreement(const DepthImage& source_depth,
                                           const RgbImage& source_color,
                                           const RgbImage& target_color,
                                           const PinholeIntrinsics& camera, double units_per_metre,
                                           std::span<const Eigen::Isometry3d> source_to_target,
                                           const PhotometricParams& params) {
  const ComparedPair pair =
      compared_pair(source_depth, source_color, target_color, camera, units_per_metre, params);
  std::vector<double> disagreement(source_to_target.size(), 0.0);
  if (pair.samples.empty()) return disagreement;
  const double cap = params.huber_levels;
  for (std::size_t m = 0; m < source_to_target.size(); ++m) {
    double sum = 0;
    for (const Sample& sample : pair.samples) {
      const Eigen::Vector3d q = source_to_target[m] * sample.point;
      double intensity = 0, gx = 0, gy = 0;
      const bool seen =
          q.z() > 0 && pair.target.sample(camera.fx * q.x() / q.z() + camera.cx,
                                          camera.fy * q.y() / q.z() + camera.cy, intensity, gx, gy);
      sum += seen ? std::min(cap, std::abs(intensity - sample.intensity)) : cap;
    }
    disagreement[m] = sum / static_cast<double>(pair.samples.size());
  }
  return disagreement;
}

PhotometricResult refine_photometrically(const DepthImage& source_depth,
                                         const RgbImage& source_color, const RgbImage& target_color,
                                         const PinholeIntrinsics& camera, double units_per_metre,
                                         const Eigen::Isometry3d& source_to_target,
                                         std::span<const se3::Vector6d> directions,
                                         const PhotometricParams& params,
                                         const se3::Matrix6d& start_information,
                                         std::size_t measured_directions) {
  require_camera_sized(source_depth, source_color, target_color, camera);
  require(params.pixel_step >= 1 && params.iterations >= 0 && params.blur_passes >= 1 &&
              units_per_metre > 0,
          "photometric refinement: pixel_step, blur_passes >= 1, iterations >= 0 and "
          "units_per_metre > 0 are required");
  PhotometricResult unrefined;
  unrefined.motion = source_to_target;
  if (directions.empty()) return unrefined;
  Prior prior(start_information, directions, params.intensity_sigma);
  const GreyImage source_grey = grey_of(source_color);
  const GreyImage target_grey = grey_of(target_color);
  const Mask kept_all(source_depth.width(), source_depth.height(), 0);
  // Coarse (wide basin), on every textured pixel. A faint texture that three passes blur under
  // the gradient threshold (a floor's wood grain: 61 pixels left of 700 on survey seed 4) skips
  // it: the fine pass then measures from ICP's answer, under the same gate.
  Eigen::Isometry3d coarse = source_to_target;
  {
    const Textured source(blurred(source_grey, params.blur_passes));
    const Textured target(blurred(target_grey, params.blur_passes));
    const std::vector<Sample> samples =
        samples_of(source_depth, source, camera, units_per_metre, params, kept_all);
    if (samples.size() >= params.min_pixels) {
      descend(samples, target, camera, directions, params, coarse, prior);
    }
  }
  // Fine (sharp minimum), from the coarse answer, without the pixels `excluded`.
  const Textured source(blurred(source_grey, 1));
  const Textured target(blurred(target_grey, 1));
  const auto fine = [&](const Mask& excluded) {
    const std::vector<Sample> samples =
        samples_of(source_depth, source, camera, units_per_metre, params, excluded);
    if (samples.size() < params.min_pixels) return unrefined;
    PhotometricResult result;
    const Sums original =
        evaluate(samples, target, camera, source_to_target, directions, params.huber_levels);
    result.rmse_before = original.count ? std::sqrt(original.squared / original.count) : 0.0;
    result.motion = coarse;
    Prior held = prior;
    const Sums sums = descend(samples, target, camera, directions, params, result.motion, held);
    result.sigma_m = motion_sigma(sums, directions, measured_directions);
    result.pixels = sums.count;
    result.rmse_after = sums.count ? std::sqrt(sums.squared / sums.count) : 0.0;
    result.refined = mean_cost(sums) + held.cost(held.amounts, sums.count) < mean_cost(original) &&
                     result.pixels >= params.min_pixels && result.sigma_m <= params.max_sigma_m;
    if (!result.refined) result.motion = source_to_target;
    return result;
  };
  const PhotometricResult masked = fine(excluded_pixels(source_depth, units_per_metre, params));
  // Where the images cannot measure the motion without the pixels beside depth edges (too few
  // left, or sigma over the gate: the 320x240 hand-held views), those pixels measure it as they
  // did before they were left out.
  if (masked.refined || !params.mask_depth_edges) return masked;
  return fine(kept_all);
}

}  // namespace kartograf::registration
