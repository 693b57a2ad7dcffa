#pragma once
// Appearance for what geometry cannot see. When a frame's surfaces leave directions of motion free
// (a wall and the floor: sliding along the wall changes no distance), ICP cannot measure them, but
// a textured floor still shows the slide. This refines only those directions of a registration by
// image intensity (a direct method restricted to the weak subspace), so that a degenerate stretch
// of a trajectory is measured instead of predicted.
//
// Residuals: for source pixels x_i (every pixel_step pixels, valid depth, intensity gradient at
// least min_gradient), r_i(s) = I_t(pi(T exp(sum_k s_k d_k) p_i)) - I_s(x_i), with I the grey level
// ((r + g + b) / 3) smoothed by a 5-tap binomial filter (applied `blur_passes` times on the coarse
// pass, once on the fine pass, which widens the basin to a few pixels), bilinear lookups, p_i the
// back-projected source pixel and d_k the given tangent directions (right perturbation, tangent
// (omega, v), geometric_information.hpp's weak_directions). Gauss-Newton on s with Huber weights
// (huber_levels grey levels); a step is kept only if it lowers the robust cost.
//
// start_information (tangent coordinates of source_to_target, 1/m^2 and 1/rad^2) is what the
// start was already measured to: the amounts s pay 0.5 s^T D^T Omega D s intensity_sigma^2 on top
// of the robust cost, so directions the start knows well move only where the images disagree
// with it clearly. Zero: the images alone. PhotometricResult::sigma_m (and so `refined`) is the
// images' own uncertainty in the first measured_directions directions, given the others: those
// the start knows (the geometry's weak but not free ones) need not be measured by the images.
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/color.hpp"
#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/core/se3.hpp"

namespace kartograf::registration {

struct PhotometricParams {
  int pixel_step = 2;
  double min_gradient = 4;  // grey levels per pixel (after smoothing)
  // Pixels with a gradient at or above this are left out (the faint texture's pass, below).
  double max_gradient = std::numeric_limits<double>::infinity();
  // A texture too faint for min_gradient (a carpet's soft blotches, 1-1.5 grey levels per pixel
  // after smoothing): where the refinement is not kept, it runs again on the pixels whose
  // gradient lies from faint_min_gradient up to min_gradient, and that answer is kept where it
  // also fits the images within faint_max_rmse grey levels (PhotometricResult::faint). Held-out
  // survey seeds 11, 24 and 26 (floor-only drives speeding up or slowing down; seed 26 between
  // striped walls that misfit): the motion model's steps were up to 3.8 cm short, their errors
  // summing to 23-59 cm over a stretch. At 0.5-1 grey levels those steps come within 1 cm; at 0.25
  // the sensor noise (about 0.2 grey levels of gradient after smoothing) misleads steps. A carpet
  // fits at 0.4-0.7 at the right motion; the gate refuses a doorway's jambs seen edge-on (seed 11,
  // frame 248: 4 cm wrong at 2.7-3.2) and a 39-degree turn's wrong basin (seed 5 every 10th frame:
  // 6 cm at 1.2-1.4). 0 turns the pass off.
  double faint_min_gradient = 0.75;
  double faint_max_rmse = 1.0;
  int iterations = 10;       // per pass
  int blur_passes = 3;       // coarse pass; the fine pass blurs once
  double huber_levels = 10;  // grey levels
  std::size_t min_pixels = 200;
  double max_depth = 4.0;  // metres
  // A refinement whose standard deviation (PhotometricResult::sigma_m) exceeds this is not a
  // measurement: on the synthetic surveys, floors with texture gave 0.04-0.2 mm, a grey floor or
  // a weak wood grain under the sensor noise 3-8 mm, with answers 2-17 cm wrong.
  double max_sigma_m = 0.001;
  // Leave out of the fine pass (and of intensity_rmse) the source pixels within 3 pixels of a
  // step in depth between two pixels that have depth (more than 3 % of the depth + 1 cm): their
  // smoothed grey level mixes two surfaces that slide apart as the camera moves (a cabinet's edge
  // against the wall behind it). On survey seed 4, frames 1041-1050, they pulled the steps
  // 0.3-1.7 cm off, a dark cabinet passing a wall. Where the fit without them fails (too few
  // pixels, or sigma over max_sigma_m: 320x240 hand-held views), it is done again with them. False
  // keeps them always, as before 2026-11-30.
  bool mask_depth_edges = true;
  // The grey-level noise a residual is taken to have when start_information is weighed against
  // the images. Set once (the synthetic camera has 2 levels per channel); the weight of the other
  // side, OdometryParams::photometric_geometry_weight, was chosen on the surveys.
  double intensity_sigma = 4.0;
  // intensity_disagreement: whether a pixel that lands outside the target image under a motion
  // counts the cap there (true), or the means are over the pixels that land inside under every
  // motion compared (false; 0 for all where fewer than min_pixels do). The cap favours a motion
  // that keeps more of the frame in view, which along a step towards a wall is a shorter one: a
  // repeated texture's period or two short (survey seed 3 every 10th frame, tour step 6: 5.26 a
  // stripe period short against 5.30 at the truth; over the pixels every shift sees, 2.4 against
  // 1.8). A mean over each motion's own pixels falls as a shift takes the hard ones out of view.
  bool unseen_at_cap = true;
};

namespace detail {
struct PreparedImages;
}

// One frame's images for the functions below, and what they derive from them, made on first use
// and kept: the grey levels, each smoothing with its gradients, the pixels beside depth edges,
// the textured pixels for each choice of parameters and camera. Comparing many motions, or a
// frame against several others (the odometry's starts, scans and re-estimates), then prepares
// each frame once. The depth (in depth units, units_per_metre) is needed where the frame is the
// source, whose pixels are moved; a target needs only its colour. Not for concurrent first use
// from several threads.
class PhotometricFrame {
 public:
  PhotometricFrame();  // none: empty()
  PhotometricFrame(RgbImage color, DepthImage depth, double units_per_metre);
  PhotometricFrame(PhotometricFrame&&) noexcept;
  PhotometricFrame& operator=(PhotometricFrame&&) noexcept;
  ~PhotometricFrame();

  bool empty() const { return color_.empty(); }
  const RgbImage& color() const { return color_; }
  const DepthImage& depth() const { return depth_; }
  double units_per_metre() const { return units_per_metre_; }
  // What the functions below derive from the images (private to them), made on first use.
  detail::PreparedImages& prepared() const;

 private:
  RgbImage color_;
  DepthImage depth_;
  double units_per_metre_ = 0;
  mutable std::unique_ptr<detail::PreparedImages> prepared_;
};

struct PhotometricResult {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  bool refined = false;    // enough textured pixels, the cost went down, sigma_m small enough
  std::size_t pixels = 0;  // residuals of the last evaluation
  double rmse_before = 0;  // grey levels, at the given motion (fine pass)
  double rmse_after = 0;
  // The refined motion's standard deviation, as the largest over the measured directions of the
  // metres it moves a point 2 m in front of the camera: rmse_after^2 (J^T W J)^-1 of the fine
  // pass, over those directions.
  double sigma_m = 0;
  // Measured by the faint texture's pass (PhotometricParams::faint_min_gradient).
  bool faint = false;
};

// The depth is in depth units (units_per_metre) on the camera's grid; both colour images too.
// Throws Error on mismatched sizes.
PhotometricResult refine_photometrically(
    const DepthImage& source_depth, const RgbImage& source_color, const RgbImage& target_color,
    const PinholeIntrinsics& camera, double units_per_metre,
    const Eigen::Isometry3d& source_to_target, std::span<const se3::Vector6d> directions,
    const PhotometricParams& params = {},
    const se3::Matrix6d& start_information = se3::Matrix6d::Zero(),
    std::size_t measured_directions = 6);

// The grey-level RMSE at each of `source_to_target` over the pixels the refinement would use,
// after one smoothing pass (PhotometricResult::rmse_before); 0 where fewer than params.min_pixels
// are textured. Compares candidate motions of the same pair, whose images are prepared once.
std::vector<double> intensity_rmse(const DepthImage& source_depth, const RgbImage& source_color,
                                   const RgbImage& target_color, const PinholeIntrinsics& camera,
                                   double units_per_metre,
                                   std::span<const Eigen::Isometry3d> source_to_target,
                                   const PhotometricParams& params = {});

// The mean grey-level disagreement min(|r|, params.huber_levels) at each of `source_to_target`
// over the same pixels, a pixel that lands outside the target image counting the cap; 0 where
// fewer than params.min_pixels are textured. A robust comparison of far-apart candidates, where
// the RMSE is decided by its outliers: on the synthetic surveys' sparse tours (a floor seen from
// 0.8 m further back, its grain aliased), the RMSE along a straight step was lowest 0.3-0.4 m
// from the true length in 4 of 14 steps checked, this within 2 cm in the 12 that moved.
std::vector<double> intensity_disagreement(const DepthImage& source_depth,
                                           const RgbImage& source_color,
                                           const RgbImage& target_color,
                                           const PinholeIntrinsics& camera, double units_per_metre,
                                           std::span<const Eigen::Isometry3d> source_to_target,
                                           const PhotometricParams& params = {});

// The three functions above on prepared frames (PhotometricFrame): the same results, each
// frame's images prepared once however often it is compared. Throws Error where a size is not
// the camera's, the source has no depth units or a gradient or depth limit is not finite.
PhotometricResult refine_photometrically(
    const PhotometricFrame& source, const PhotometricFrame& target, const PinholeIntrinsics& camera,
    const Eigen::Isometry3d& source_to_target, std::span<const se3::Vector6d> directions,
    const PhotometricParams& params = {},
    const se3::Matrix6d& start_information = se3::Matrix6d::Zero(),
    std::size_t measured_directions = 6);
std::vector<double> intensity_rmse(const PhotometricFrame& source, const PhotometricFrame& target,
                                   const PinholeIntrinsics& camera,
                                   std::span<const Eigen::Isometry3d> source_to_target,
                                   const PhotometricParams& params = {});
std::vector<double> intensity_disagreement(const PhotometricFrame& source,
                                           const PhotometricFrame& target,
                                           const PinholeIntrinsics& camera,
                                           std::span<const Eigen::Isometry3d> source_to_target,
                                           const PhotometricParams& params = {});

}  // namespace kartograf::registration
