#pragma once
// How well a frame's own geometry pins down each direction of motion, from a coarse pyramid level.
//
// ICP's J^T W J (icp_result.hpp) is built from the finest level's normals. On Kinect-class depth,
// 4-neighbour normals at 320x240 or 640x480 scatter by tens of degrees, and that scatter reads as
// constraint: a view of one wall and the floor, which leaves the motion along their intersection
// free, gave a balanced eigenvalue ratio of 0.07 from ICP's sums at 320x240, and 0.0004 from the
// 80x60 level's normals (averages over 8x8 pixels). Odometry and loop closure judge degeneracy and
// weight pose-graph edges with this honest version.
//
// For the valid points p of a cloud with valid normals n (its own frame) and weights w (the depth
// weights of depth_weighted_finder.hpp, or 1):
//   H = sum w J J^T / sum w,   J = [p x n; n]
// is the mean Gauss-Newton information of the plane distances for the right perturbation
// T exp(xi), xi = (omega, v), of a motion T applied to the cloud (the source of a registration):
// with the source frame j and the target frame i, that of the pose-graph edge from i to j.
// `about_centre` is the same sum with p taken relative to the weighted centroid; degeneracy is
// analyse_degeneracy() of it.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "kartograf/core/intrinsics.hpp"
#include "kartograf/core/se3.hpp"
#include "kartograf/registration/correspondence_finder.hpp"
#include "kartograf/registration/rigid_solvers.hpp"

namespace kartograf::registration {

struct GeometricInformation {
  se3::Matrix6d information = se3::Matrix6d::Zero();   // right perturbation, per unit weight
  se3::Matrix6d about_centre = se3::Matrix6d::Zero();  // per unit weight
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();    // weighted centroid
  DegeneracyReport degeneracy;
  std::size_t points = 0;  // points with a normal
  double weight_sum = 0;
};

// cloud needs points and normals (downloaded from a device). reference_depth > 0 applies the depth
// weights of DepthWeightedFinder; 0 weighs every point 1.
// `keep` (one entry per point; empty: all) restricts the sums to the points it marks.
GeometricInformation geometric_information(const CloudView& cloud, double reference_depth,
                                           double min_eigenvalue_ratio,
                                           std::span<const std::uint8_t> keep = {});

// Where `source_to_target` puts a point of `source` (a frame's pyramid level) in the view of
// `target` (the same level of another frame, an image of `camera`'s size): outside it or onto a
// pixel without depth (unseen); within max_gap_m of the pixel's depth along the view axis
// (agrees); nearer than that, where the target camera saw a surface behind it, which the point
// would have hidden (seen_through: the motion contradicts the target's view); or farther (hidden
// behind what the target saw: no contradiction).
enum class ViewRelation : std::uint8_t { unseen, agrees, seen_through, hidden };
std::vector<ViewRelation> view_relations(const CloudView& source, const CloudView& target,
                                         const PinholeIntrinsics& camera,
                                         const Eigen::Isometry3d& source_to_target,
                                         double max_gap_m);

// The points of `source` (a frame's pyramid level) that `source_to_target` maps into the view of
// `target` (the same level of another frame, an image of `camera`'s size): they land inside the
// image on a pixel with depth, within max_gap_m of it along the view axis. What a registration of
// the two frames can match: at a wide turn only part of the frame.
std::vector<std::uint8_t> overlapping_points(const CloudView& source, const CloudView& target,
                                             const PinholeIntrinsics& camera,
                                             const Eigen::Isometry3d& source_to_target,
                                             double max_gap_m);

// GeometricInformation::information without its weak directions (balanced eigenvalue below
// min_eigenvalue_ratio x the largest, about the centroid): what a registration whose weak
// directions came from elsewhere (keep_constrained_directions) measured.
se3::Matrix6d constrained_information(const GeometricInformation& geometry,
                                      double min_eigenvalue_ratio);

// The information (per unit weight, GeometricInformation::information's coordinates) of a motion
// prior that is isotropic about the camera: rotations and camera translations equally certain in
// the geometry's balanced units, each `strength` x the mean direction's information. Added to
// ICP (icp.hpp's IcpPrior) with the motion model as its mean, it decides the directions the
// geometry leaves free and barely moves the others. About the camera, not the centroid: the
// motion model predicts the camera's own motion, so a turn it missed (a rotation the geometry
// measures) must not shift the camera sideways, as holding the translation at the centroid does.
se3::Matrix6d motion_prior_information(const GeometricInformation& geometry, double strength);
// The same with the camera's rotations and translations each at their own strength.
struct MotionPriorStrength {
  double rotation = 0;
  double translation = 0;
};
se3::Matrix6d motion_prior_information(const GeometricInformation& geometry,
                                       const MotionPriorStrength& strength);

// The weak directions (balanced eigenvalue below min_eigenvalue_ratio x the largest) as tangent
// vectors of the right perturbation of a motion applied to the cloud, weakest first.
std::vector<se3::Vector6d> weak_directions(const GeometricInformation& geometry,
                                           double min_eigenvalue_ratio);

// How much `geometry` constrains a translation of the source along `direction` (its camera
// frame, unit): the translation information along it over the largest eigenvalue of the
// translation information. 0: free (a floor alone leaves a slide over it), 1: as constrained as
// any translation. 0 where the geometry constrains no translation at all.
double translation_constraint(const GeometricInformation& geometry,
                              const Eigen::Vector3d& direction);

// The translations of the source (its camera frame, unit) that `geometry` leaves free: the
// eigenvectors of its translation information below min_eigenvalue_ratio x the largest, weakest
// first (a floor and a wall: the line they meet along; a floor alone: two). None where the
// geometry constrains no translation at all.
std::vector<Eigen::Vector3d> free_translations(const GeometricInformation& geometry,
                                               double min_eigenvalue_ratio);

// `information` restricted to `directions` (tangent vectors, as weak_directions gives them): it
// says as much about their amounts and nothing about the directions off their span (the
// least-squares amounts of a perturbation are what it weighs).
se3::Matrix6d information_along(const se3::Matrix6d& information,
                                std::span<const se3::Vector6d> directions);

// The motion that keeps `measured` in the well-constrained directions of `geometry` and takes
// `predicted` (e.g. the motion model's) in those whose balanced eigenvalue is below
// min_eigenvalue_ratio x the largest: the difference log(measured^-1 predicted) is projected on
// the weak eigenvectors (about the centroid, in balanced coordinates). Both motions map the
// geometry's cloud (the source) into the target.
Eigen::Isometry3d keep_constrained_directions(const Eigen::Isometry3d& measured,
                                              const Eigen::Isometry3d& predicted,
                                              const GeometricInformation& geometry,
                                              double min_eigenvalue_ratio);

}  // namespace kartograf::registration
