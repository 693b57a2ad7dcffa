#include "kartograf/registration/photometric_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "kartograf/core/error.hpp"
#include "photometric_images.hpp"

namespace kartograf::registration {

namespace {

using detail::GreyImage;
using detail::Mask;
using detail::Sample;
using detail::Textured;

// Robust Gauss-Newton sums of all residuals at `motion`.
struct Sums {
  Eigen::MatrixXd jtj;
  Eigen::VectorXd jtr;
  double cost = 0;
  double squared = 0;
  std::size_t count = 0;
};

Sums evaluate(std::span<const Sample> samples, const Textured& target, const PinholeIntrinsics& k,
              const Eigen::Isometry3d& motion, std::span<const se3::Vector6d> directions,
              double huber) {
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

// The frame's grey levels after `passes` binomial passes, with their gradients.
const Textured& smoothed(const PhotometricFrame& frame, int passes) {
  detail::PreparedImages& prepared = frame.prepared();
  if (!prepared.grey) prepared.grey = detail::grey_of(frame.color());
  auto found = prepared.smoothed.find(passes);
  if (found == prepared.smoothed.end()) {
    found = prepared.smoothed.try_emplace(passes, detail::blurred(*prepared.grey, passes)).first;
  }
  return found->second;
}

// No pixel left out.
const Mask& kept_all(const PhotometricFrame& frame) {
  detail::PreparedImages& prepared = frame.prepared();
  if (!prepared.kept_all)
    prepared.kept_all = Mask(frame.depth().width(), frame.depth().height(), 0);
  return *prepared.kept_all;
}

// The pixels beside depth edges (detail::near_depth_edges), which the fine pass and the
// comparisons leave out where params.mask_depth_edges.
const Mask& depth_edges(const PhotometricFrame& frame) {
  detail::PreparedImages& prepared = frame.prepared();
  if (!prepared.near_depth_edges) {
    prepared.near_depth_edges = detail::near_depth_edges(frame.depth(), frame.units_per_metre());
  }
  return *prepared.near_depth_edges;
}

std::vector<Sample> samples_of(const DepthImage& depth, const Textured& source,
                               const PinholeIntrinsics& k, double units_per_metre,
                               const PhotometricParams& params, const Mask& excluded) {
  std::vector<Sample> samples;
  const double min_squared = params.min_gradient * params.min_gradient;
  const double max_squared = params.max_gradient * params.max_gradient;
  for (int y = 2; y + 2 < depth.height(); y += params.pixel_step) {
    for (int x = 2; x + 2 < depth.width(); x += params.pixel_step) {
      const double z = depth(x, y) / units_per_metre;
      if (depth(x, y) == 0 || z > params.max_depth || excluded(x, y)) continue;
      const double gx = source.dx(x, y), gy = source.dy(x, y);
      const double squared = gx * gx + gy * gy;
      if (squared < min_squared || squared >= max_squared) continue;
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
Sums descend(std::span<const Sample> samples, const Textured& target, const PinholeIntrinsics& k,
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

// The sizes the functions below need: the camera's, with depth in the source.
void require_camera_sized(const PhotometricFrame& source, const PhotometricFrame& target,
                          const PinholeIntrinsics& camera) {
  const auto same_size = [&](int w, int h) { return w == camera.width && h == camera.height; };
  require(same_size(source.depth().width(), source.depth().height()) &&
              same_size(source.color().width(), source.color().height()) &&
              same_size(target.color().width(), target.color().height()),
          "photometric refinement: depth and colour images must have the camera's size " +
              std::to_string(camera.width) + "x" + std::to_string(camera.height));
  require(source.units_per_metre() > 0, "photometric refinement: units_per_metre must be > 0");
}

// The limits that pick the samples (and key the frame's kept samples) must be numbers.
void require_finite_limits(const PhotometricParams& params) {
  require(std::isfinite(params.min_gradient) && std::isfinite(params.max_depth) &&
              !std::isnan(params.max_gradient),
          "photometric refinement: min_gradient and max_depth must be finite, max_gradient a "
          "number");
}

// The source's textured pixels after `passes` smoothing passes, without those beside depth edges
// where `masked` (and params.mask_depth_edges), gathered once per frame and choice.
const std::vector<Sample>& samples_for(const PhotometricFrame& source, int passes, bool masked,
                                       const PinholeIntrinsics& k,
                                       const PhotometricParams& params) {
  require_finite_limits(params);
  masked = masked && params.mask_depth_edges;
  const detail::SampleChoice choice{.passes = passes,
                                    .masked = masked,
                                    .pixel_step = params.pixel_step,
                                    .min_gradient = params.min_gradient,
                                    .max_gradient = params.max_gradient,
                                    .max_depth = params.max_depth,
                                    .fx = k.fx,
                                    .fy = k.fy,
                                    .cx = k.cx,
                                    .cy = k.cy};
  auto& cache = source.prepared().samples;
  auto found = cache.find(choice);
  if (found == cache.end()) {
    const Mask& excluded = masked ? depth_edges(source) : kept_all(source);
    found = cache
                .try_emplace(choice, samples_of(source.depth(), smoothed(source, passes), k,
                                                source.units_per_metre(), params, excluded))
                .first;
  }
  return found->second;
}

// The samples intensity_rmse and intensity_disagreement compare motions on: one smoothing pass,
// the pixels beside depth edges left out (params.mask_depth_edges); none where fewer than
// params.min_pixels.
std::span<const Sample> compared_samples(const PhotometricFrame& source,
                                         const PhotometricFrame& target,
                                         const PinholeIntrinsics& camera,
                                         const PhotometricParams& params) {
  require_camera_sized(source, target, camera);
  const std::vector<Sample>& samples = samples_for(source, 1, true, camera, params);
  if (samples.size() < params.min_pixels) return {};
  return samples;
}

}  // namespace

PhotometricFrame::PhotometricFrame() = default;
PhotometricFrame::PhotometricFrame(RgbImage color, DepthImage depth, double units_per_metre)
    : color_(std::move(color)), depth_(std::move(depth)), units_per_metre_(units_per_metre) {}
PhotometricFrame::PhotometricFrame(PhotometricFrame&&) noexcept = default;
PhotometricFrame& PhotometricFrame::operator=(PhotometricFrame&&) noexcept = default;
PhotometricFrame::~PhotometricFrame() = default;

detail::PreparedImages& PhotometricFrame::prepared() const {
  if (!prepared_) prepared_ = std::make_unique<detail::PreparedImages>();
  return *prepared_;
}

std::vector<double> intensity_rmse(const PhotometricFrame& source, const PhotometricFrame& target,
                                   const PinholeIntrinsics& camera,
                                   std::span<const Eigen::Isometry3d> source_to_target,
                                   const PhotometricParams& params) {
  const std::span<const Sample> samples = compared_samples(source, target, camera, params);
  std::vector<double> rmse(source_to_target.size(), 0.0);
  if (samples.empty()) return rmse;
  const Textured& onto = smoothed(target, 1);
  for (std::size_t m = 0; m < source_to_target.size(); ++m) {
    const Sums sums = evaluate(samples, onto, camera, source_to_target[m], {}, params.huber_levels);
    if (sums.count >= params.min_pixels) rmse[m] = std::sqrt(sums.squared / sums.count);
  }
  return rmse;
}

std::vector<double> intensity_disagreement(const PhotometricFrame& source,
                                           const PhotometricFrame& target,
                                           const PinholeIntrinsics& camera,
                                           std::span<const Eigen::Isometry3d> source_to_target,
                                           const PhotometricParams& params) {
  const std::span<const Sample> samples = compared_samples(source, target, camera, params);
  std::vector<double> disagreement(source_to_target.size(), 0.0);
  if (samples.empty()) return disagreement;
  const Textured& onto = smoothed(target, 1);
  const double cap = params.huber_levels;
  // Each sample's capped difference under each motion (< 0: outside the target's view).
  const auto difference = [&](const Sample& sample, const Eigen::Isometry3d& motion) {
    const Eigen::Vector3d q = motion * sample.point;
    double intensity = 0, gx = 0, gy = 0;
    const bool seen =
        q.z() > 0 && onto.sample(camera.fx * q.x() / q.z() + camera.cx,
                                 camera.fy * q.y() / q.z() + camera.cy, intensity, gx, gy);
    return seen ? std::min(cap, std::abs(intensity - sample.intensity)) : -1.0;
  };
  if (params.unseen_at_cap) {
    for (std::size_t m = 0; m < source_to_target.size(); ++m) {
      double sum = 0;
      for (const Sample& sample : samples) {
        const double d = difference(sample, source_to_target[m]);
        sum += d < 0 ? cap : d;
      }
      disagreement[m] = sum / static_cast<double>(samples.size());
    }
    return disagreement;
  }
  std::vector<double> sums(source_to_target.size(), 0.0), row(source_to_target.size());
  std::size_t shared = 0;
  for (const Sample& sample : samples) {
    bool everywhere = true;
    for (std::size_t m = 0; m < source_to_target.size() && everywhere; ++m) {
      row[m] = difference(sample, source_to_target[m]);
      everywhere = row[m] >= 0;
    }
    if (!everywhere) continue;
    ++shared;
    for (std::size_t m = 0; m < source_to_target.size(); ++m) sums[m] += row[m];
  }
  if (shared < params.min_pixels) return disagreement;
  for (std::size_t m = 0; m < source_to_target.size(); ++m) {
    disagreement[m] = sums[m] / static_cast<double>(shared);
  }
  return disagreement;
}

namespace {

// One refinement on the pixels params' gradient limits pick: the coarse pass, then the fine one.
PhotometricResult refine_on_gradients(
    const PhotometricFrame& source, const PhotometricFrame& target, const PinholeIntrinsics& camera,
    const Eigen::Isometry3d& source_to_target, std::span<const se3::Vector6d> directions,
    const PhotometricParams& params, const se3::Matrix6d& start_information,
    std::size_t measured_directions) {
  PhotometricResult unrefined;
  unrefined.motion = source_to_target;
  if (directions.empty()) return unrefined;
  Prior prior(start_information, directions, params.intensity_sigma);
  // Coarse (wide basin), on every textured pixel. A faint texture that three passes blur under
  // the gradient threshold (a floor's wood grain: 61 pixels left of 700 on survey seed 4) skips
  // it: the fine pass then measures from ICP's answer, under the same gate.
  Eigen::Isometry3d coarse = source_to_target;
  if (const std::vector<Sample>& wide =
          samples_for(source, params.blur_passes, false, camera, params);
      wide.size() >= params.min_pixels) {
    descend(wide, smoothed(target, params.blur_passes), camera, directions, params, coarse, prior);
  }
  // Fine (sharp minimum), from the coarse answer, without the pixels beside depth edges.
  const Textured& onto = smoothed(target, 1);
  const auto fine = [&](bool masked) {
    const std::vector<Sample>& sharp = samples_for(source, 1, masked, camera, params);
    if (sharp.size() < params.min_pixels) return unrefined;
    PhotometricResult result;
    const Sums original =
        evaluate(sharp, onto, camera, source_to_target, directions, params.huber_levels);
    result.rmse_before = original.count ? std::sqrt(original.squared / original.count) : 0.0;
    result.motion = coarse;
    Prior held = prior;
    const Sums sums = descend(sharp, onto, camera, directions, params, result.motion, held);
    result.sigma_m = motion_sigma(sums, directions, measured_directions);
    result.pixels = sums.count;
    result.rmse_after = sums.count ? std::sqrt(sums.squared / sums.count) : 0.0;
    result.refined = mean_cost(sums) + held.cost(held.amounts, sums.count) < mean_cost(original) &&
                     result.pixels >= params.min_pixels && result.sigma_m <= params.max_sigma_m;
    if (!result.refined) result.motion = source_to_target;
    return result;
  };
  const PhotometricResult masked = fine(true);
  // Where the images cannot measure the motion without the pixels beside depth edges (too few
  // left, or sigma over the gate: the 320x240 hand-held views), those pixels measure it as they
  // did before they were left out.
  if (masked.refined || !params.mask_depth_edges) return masked;
  return fine(false);
}

// PhotometricParams::faint_min_gradient: whether the faint texture's pass runs.
bool measures_faint_texture(const PhotometricParams& params) {
  return params.faint_min_gradient > 0 && params.faint_min_gradient < params.min_gradient;
}

}  // namespace

PhotometricResult refine_photometrically(
    const PhotometricFrame& source, const PhotometricFrame& target, const PinholeIntrinsics& camera,
    const Eigen::Isometry3d& source_to_target, std::span<const se3::Vector6d> directions,
    const PhotometricParams& params, const se3::Matrix6d& start_information,
    std::size_t measured_directions) {
  require_camera_sized(source, target, camera);
  require(params.pixel_step >= 1 && params.iterations >= 0 && params.blur_passes >= 1,
          "photometric refinement: pixel_step, blur_passes >= 1 and iterations >= 0 are required");
  require(std::isfinite(params.faint_min_gradient) && std::isfinite(params.faint_max_rmse),
          "photometric refinement: faint_min_gradient and faint_max_rmse must be finite");
  const PhotometricResult textured =
      refine_on_gradients(source, target, camera, source_to_target, directions, params,
                          start_information, measured_directions);
  if (textured.refined || directions.empty() || !measures_faint_texture(params)) return textured;
  // The texture under min_gradient alone: the pixels above it did not measure the motion.
  PhotometricParams faint = params;
  faint.min_gradient = params.faint_min_gradient;
  faint.max_gradient = std::min(params.min_gradient, params.max_gradient);
  PhotometricResult result =
      refine_on_gradients(source, target, camera, source_to_target, directions, faint,
                          start_information, measured_directions);
  if (!result.refined || result.rmse_after > params.faint_max_rmse) return textured;
  result.faint = true;
  return result;
}

// The same on images given one by one (each call prepares them).
PhotometricResult refine_photometrically(const DepthImage& source_depth,
                                         const RgbImage& source_color, const RgbImage& target_color,
                                         const PinholeIntrinsics& camera, double units_per_metre,
                                         const Eigen::Isometry3d& source_to_target,
                                         std::span<const se3::Vector6d> directions,
                                         const PhotometricParams& params,
                                         const se3::Matrix6d& start_information,
                                         std::size_t measured_directions) {
  return refine_photometrically(PhotometricFrame(source_color, source_depth, units_per_metre),
                                PhotometricFrame(target_color, {}, units_per_metre), camera,
                                source_to_target, directions, params, start_information,
                                measured_directions);
}

std::vector<double> intensity_rmse(const DepthImage& source_depth, const RgbImage& source_color,
                                   const RgbImage& target_color, const PinholeIntrinsics& camera,
                                   double units_per_metre,
                                   std::span<const Eigen::Isometry3d> source_to_target,
                                   const PhotometricParams& params) {
  return intensity_rmse(PhotometricFrame(source_color, source_depth, units_per_metre),
                        PhotometricFrame(target_color, {}, units_per_metre), camera,
                        source_to_target, params);
}

std::vector<double> intensity_disagreement(const DepthImage& source_depth,
                                           const RgbImage& source_color,
                                           const RgbImage& target_color,
                                           const PinholeIntrinsics& camera, double units_per_metre,
                                           std::span<const Eigen::Isometry3d> source_to_target,
                                           const PhotometricParams& params) {
  return intensity_disagreement(PhotometricFrame(source_color, source_depth, units_per_metre),
                                PhotometricFrame(target_color, {}, units_per_metre), camera,
                                source_to_target, params);
}

}  // namespace kartograf::registration
