#pragma once
// The ICP engine (docs/methods.md M3): one coarse-to-fine loop whose parts are swapped, not copied.
//
//   correspondences  a CorrespondenceFinder (correspondence_finder.hpp); default: projective
//                    association for organized frames (projective_association.hpp)
//   point selection  uniform 1-in-k per level (IcpLevelParams::subsample)
//   rejection        per-level distance gate, normal-angle gate, robust kernel (robust_kernel.hpp)
//   error metric     point-to-point (closed-form SVD) or point-to-plane (Gauss-Newton)
//   convergence      per-level iteration limit and update tolerances (ConvergenceCriteria)
//
// Each iteration: finder.find() fills device buffers of pairs, IcpReduction sums them on the
// device (robust weights included), and only those sums (<= 32 doubles) come back to the host,
// where the solver (rigid_solvers.hpp) updates T <- Delta T. Points, normals and correspondences
// never leave the device. Levels run coarsest first; the finest level's last pairs give fitness,
// RMSE, information and degeneracy (icp_result.hpp). On the CPU backend the loops run on one
// thread unless KARTOGRAF_CPU_THREADS=n (results are identical for any n; one thread is faster
// on a machine shared with other work, n = cores on a dedicated one).
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/compute/context.hpp"
#include "kartograf/registration/correspondence_finder.hpp"
#include "kartograf/registration/frame_pyramid.hpp"
#include "kartograf/registration/icp_result.hpp"
#include "kartograf/registration/icp_sums.hpp"
#include "kartograf/registration/robust_kernel.hpp"

namespace kartograf::registration {

enum class ErrorMetric { point_to_point, point_to_plane };

struct IcpLevelParams {
  int max_iterations = 10;
  int subsample = 1;           // use 1 source point in k (the M3 paper uses 1 in 10)
  double max_distance = 0.1;   // metres: pairs farther apart are rejected
  double robust_scale = 0.05;  // metres: the robust kernel's c on this level
  int search_radius = 0;       // AssociationParams::search_radius (point-to-point wants 1-2)
};

// A level stops when one update rotates by less than rotation_tolerance AND translates (at the
// pivot) by less than translation_tolerance.
struct ConvergenceCriteria {
  double rotation_tolerance = 1e-5;     // radians
  double translation_tolerance = 1e-5;  // metres
};

// Three levels for frame-to-frame odometry of 640x480 frames at 30 Hz (index 0 = finest): a
// wide-gated pass on 1 point in 2 at 160x120, then 1 in 4 at 320x240 and 1 in 10 at 640x480.
std::vector<IcpLevelParams> odometry_levels();

struct IcpParams {
  ErrorMetric metric = ErrorMetric::point_to_plane;
  RobustKernel robust_kernel = RobustKernel::none;
  double max_normal_angle_deg = 30;  // normal gate of the finder; >= 180 turns it off
  // levels[l] runs on pyramid level l (0 = full resolution); one entry: no pyramid.
  std::vector<IcpLevelParams> levels = odometry_levels();
  ConvergenceCriteria convergence;
  // Degenerate when the balanced J^T J's smallest / largest eigenvalue is below this.
  double min_eigenvalue_ratio = 0.01;
};

// A Gaussian prior on the result (point-to-plane only): cost
//   1/2 e^T (W information) e,  e = log(mean^-1 T),
// T the source-to-target estimate, e its right perturbation (source frame, (omega, v)), W the
// pairs' weight sum on the level being solved: `information` is per unit pair weight, so a prior
// of the geometric information's scale (geometric_information.hpp) speaks like the pairs do. The
// odometry pins the weak directions of degenerate views to the motion model with it, so ICP
// never slides along them (sliding there also moves its pairs and corrupts the other directions).
struct IcpPrior {
  Eigen::Isometry3d mean = Eigen::Isometry3d::Identity();
  se3::Matrix6d information = se3::Matrix6d::Zero();
};

class IcpEngine {
 public:
  // Throws Error on invalid parameters. finder: null selects ProjectiveAssociation.
  IcpEngine(const compute::Context& context, IcpParams params = {},
            std::unique_ptr<CorrespondenceFinder> finder = nullptr);

  // Aligns source to target from `initial` (source-to-target); both pyramids need at least
  // params().levels.size() levels. Throws Error on missing inputs (e.g. point-to-plane without
  // target normals); a run without enough pairs returns converged = false.
  IcpResult align(const FramePyramid& source, const FramePyramid& target,
                  const Eigen::Isometry3d& initial = Eigen::Isometry3d::Identity());
  // The same over any clouds the finder accepts (index 0 = finest).
  IcpResult align(std::span<const CloudView> source_levels,
                  std::span<const CloudView> target_levels,
                  const Eigen::Isometry3d& initial = Eigen::Isometry3d::Identity());
  // The same with a prior added to every point-to-plane step (ignored by point-to-point).
  IcpResult align(std::span<const CloudView> source_levels,
                  std::span<const CloudView> target_levels, const Eigen::Isometry3d& initial,
                  const IcpPrior& prior);

  const IcpParams& params() const { return params_; }
  // The pair gate of `level` for the following alignments (the odometry widens the finest one
  // for deep frames, depth_noise_gate.hpp). Throws Error on a level out of range or a gate not
  // finite and > 0.
  void set_max_distance(std::size_t level, double metres);

 private:
  struct LastSums;
  struct LevelOutcome;
  LevelOutcome run_level(int level, const CloudView& source, const CloudView& target,
                         const Eigen::Vector3d& centroid, Eigen::Isometry3d& pose,
                         const IcpPrior* prior);
  IcpResult align_levels(std::span<const CloudView> source_levels,
                         std::span<const CloudView> target_levels, const Eigen::Isometry3d& initial,
                         const IcpPrior* prior);
  void evaluate(const CloudView& source, const CloudView& target, const Eigen::Vector3d& centroid,
                const LevelOutcome& finest, IcpResult& result);
  Correspondences pairs_of(int level, const CloudView& source, const CloudView& target,
                           const Eigen::Isometry3d& pose) const;
  AssociationParams gates_of(int level) const;

  IcpParams params_;
  std::unique_ptr<CorrespondenceFinder> finder_;
  IcpReduction reduction_;
  // One per level, kept between calls: steady-state alignments allocate nothing.
  std::vector<CorrespondenceBuffers> buffers_;
};

}  // namespace kartograf::registration
