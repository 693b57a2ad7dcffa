#include "kartograf/registration/geometric_information.hpp"

#include <cmath>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "kartograf/geometry/pixel_projection.hpp"
#include "kartograf/registration/depth_weighted_finder.hpp"

namespace kartograf::registration {

namespace {

// The cloud's points and normals on the host (in place on the CPU backend).
struct HostCloud {
  compute::HostView<Point4f> points;
  compute::HostView<Point4f> normals;
};

HostCloud host_cloud(const CloudView& cloud) {
  require(cloud.points && cloud.normals && cloud.normals->size() == cloud.points->size(),
          "geometric information: the cloud needs points and one normal per point");
  return {compute::read_on_host(*cloud.points), compute::read_on_host(*cloud.normals)};
}

// Balanced coordinates of analyse_degeneracy: rotations scaled by the length L.
se3::Vector6d balance_scale(double rotation_scale) {
  se3::Vector6d scale;
  scale << Eigen::Vector3d::Constant(1.0 / rotation_scale), Eigen::Vector3d::Ones();
  return scale;
}

// The balanced, trace-normalised Hessian about the centre (analyse_degeneracy's) and its
// eigen-decomposition: B = S H_c S / normaliser, S = diag(scale).
struct BalancedEigen {
  bool valid = false;
  se3::Vector6d scale = se3::Vector6d::Ones();
  double normaliser = 1;
  Eigen::SelfAdjointEigenSolver<se3::Matrix6d> solver;
};

BalancedEigen balanced_eigen(const GeometricInformation& geometry) {
  BalancedEigen result;
  if (!(geometry.degeneracy.rotation_scale > 0)) return result;
  result.scale = balance_scale(geometry.degeneracy.rotation_scale);
  se3::Matrix6d balanced =
      result.scale.asDiagonal() * geometry.about_centre * result.scale.asDiagonal();
  result.normaliser = balanced.trace() / 6.0;
  if (!(result.normaliser > 0)) return result;
  balanced /= result.normaliser;
  result.solver.compute(balanced);
  result.valid = true;
  return result;
}

Eigen::Isometry3d centre_pose(const GeometricInformation& geometry) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = geometry.centre;
  return pose;
}

}  // namespace

GeometricInformation geometric_information(const CloudView& cloud, double reference_depth,
                                           double min_eigenvalue_ratio,
                                           std::span<const std::uint8_t> keep) {
  const HostCloud host = host_cloud(cloud);
  require(keep.empty() || keep.size() == host.points.size(),
          "geometric information: the mask needs one entry per point");
  GeometricInformation result;
  const auto counts = [&](std::size_t i) {
    return (keep.empty() || keep[i]) && is_valid(host.points[i]) && is_valid(host.normals[i]);
  };
  const auto weight_of = [&](const Point4f& p) {
    return reference_depth > 0
               ? static_cast<double>(DepthWeightedFinder::weight(p.z(), reference_depth))
               : 1.0;
  };
  Eigen::Vector3d weighted_sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < host.points.size(); ++i) {
    if (!counts(i)) continue;
    const double w = weight_of(host.points[i]);
    weighted_sum += w * host.points[i].head<3>().cast<double>();
    result.weight_sum += w;
    ++result.points;
  }
  if (!(result.weight_sum > 0)) return result;
  result.centre = weighted_sum / result.weight_sum;
  for (std::size_t i = 0; i < host.points.size(); ++i) {
    if (!counts(i)) continue;
    const double w = weight_of(host.points[i]);
    const Eigen::Vector3d p = host.points[i].head<3>().cast<double>();
    const Eigen::Vector3d n = host.normals[i].head<3>().cast<double>();
    se3::Vector6d j;
    j << p.cross(n), n;
    result.information.noalias() += w * j * j.transpose();
    j.head<3>() = (p - result.centre).cross(n);
    result.about_centre.noalias() += w * j * j.transpose();
  }
  result.information /= result.weight_sum;
  result.about_centre /= result.weight_sum;
  result.degeneracy = analyse_degeneracy(result.about_centre, min_eigenvalue_ratio);
  return result;
}

std::vector<ViewRelation> view_relations(const CloudView& source, const CloudView& target,
                                         const PinholeIntrinsics& camera,
                                         const Eigen::Isometry3d& source_to_target,
                                         double max_gap_m) {
  const compute::HostView<Point4f> from = compute::read_on_host(*source.points);
  const compute::HostView<Point4f> onto = compute::read_on_host(*target.points);
  require(onto.size() == static_cast<std::size_t>(camera.width) * camera.height,
          "view relations: the target must be an image of the camera's size");
  const Eigen::Isometry3f motion = source_to_target.cast<float>();
  std::vector<ViewRelation> relations(from.size(), ViewRelation::unseen);
  for (std::size_t i = 0; i < from.size(); ++i) {
    if (!is_valid(from[i])) continue;
    const Eigen::Vector3f q = motion * from[i].head<3>();
    const std::optional<Eigen::Vector2i> pixel = geometry::nearest_pixel(camera, q.cast<double>());
    if (!pixel) continue;
    const Point4f& seen = onto[static_cast<std::size_t>(pixel->y()) * camera.width +
                               static_cast<std::size_t>(pixel->x())];
    if (!is_valid(seen)) continue;
    const float gap = q.z() - seen.z();
    relations[i] = std::abs(gap) <= max_gap_m ? ViewRelation::agrees
                   : gap < 0                  ? ViewRelation::seen_through
                                              : ViewRelation::hidden;
  }
  return relations;
}

std::vector<std::uint8_t> overlapping_points(const CloudView& source, const CloudView& target,
                                             const PinholeIntrinsics& camera,
                                             const Eigen::Isometry3d& source_to_target,
                                             double max_gap_m) {
  const std::vector<ViewRelation> relations =
      view_relations(source, target, camera, source_to_target, max_gap_m);
  std::vector<std::uint8_t> keep(relations.size(), 0);
  for (std::size_t i = 0; i < relations.size(); ++i) {
    keep[i] = relations[i] == ViewRelation::agrees;
  }
  return keep;
}

namespace {

// A matrix in balanced, normalised coordinates about the centre (BalancedEigen's) back in those
// of GeometricInformation::information: xi = Ad(T(c)) xi_c, so H = A^T H_c A, A = Ad(T(c))^-1.
se3::Matrix6d from_balanced(const BalancedEigen& eigen, const GeometricInformation& geometry,
                            const se3::Matrix6d& balanced) {
  const se3::Vector6d inverse_scale = eigen.scale.cwiseInverse();
  const se3::Matrix6d about_centre =
      eigen.normaliser * (inverse_scale.asDiagonal() * balanced * inverse_scale.asDiagonal());
  const se3::Matrix6d to_centre = se3::adjoint(centre_pose(geometry).inverse());
  return to_centre.transpose() * about_centre * to_centre;
}

// The balanced eigen-decomposition's part on its strong (weak: false) or weak (true)
// eigenvectors, each weighted by weight(eigenvalue).
template <typename Weight>
se3::Matrix6d balanced_part(const BalancedEigen& eigen, double min_eigenvalue_ratio, bool weak,
                            Weight weight) {
  se3::Matrix6d part = se3::Matrix6d::Zero();
  const double largest = eigen.solver.eigenvalues()(5);
  for (int k = 0; k < 6; ++k) {
    const double lambda = eigen.solver.eigenvalues()(k);
    if ((lambda < min_eigenvalue_ratio * largest) != weak) continue;
    const se3::Vector6d u = eigen.solver.eigenvectors().col(k);
    part += weight(lambda) * u * u.transpose();
  }
  return part;
}

}  // namespace

se3::Matrix6d constrained_information(const GeometricInformation& geometry,
                                      double min_eigenvalue_ratio) {
  const BalancedEigen eigen = balanced_eigen(geometry);
  if (!eigen.valid) return se3::Matrix6d::Zero();
  const se3::Matrix6d strong =
      balanced_part(eigen, min_eigenvalue_ratio, false, [](double lambda) { return lambda; });
  return from_balanced(eigen, geometry, strong);
}

se3::Matrix6d motion_prior_information(const GeometricInformation& geometry, double strength) {
  return motion_prior_information(geometry, MotionPriorStrength{strength, strength});
}

se3::Matrix6d motion_prior_information(const GeometricInformation& geometry,
                                       const MotionPriorStrength& strength) {
  const BalancedEigen eigen = balanced_eigen(geometry);
  if (!eigen.valid) return se3::Matrix6d::Zero();
  // strength x the identity in balanced coordinates (trace 6: the mean direction's information),
  // about the camera: H = S^-1 (strength normaliser I) S^-1, rotations first.
  se3::Vector6d strengths;
  strengths << Eigen::Vector3d::Constant(strength.rotation),
      Eigen::Vector3d::Constant(strength.translation);
  const se3::Vector6d inverse_scale = eigen.scale.cwiseInverse();
  return eigen.normaliser *
         strengths.cwiseProduct(inverse_scale.cwiseProduct(inverse_scale)).asDiagonal();
}

std::vector<se3::Vector6d> weak_directions(const GeometricInformation& geometry,
                                           double min_eigenvalue_ratio) {
  std::vector<se3::Vector6d> directions;
  const BalancedEigen eigen = balanced_eigen(geometry);
  if (!eigen.valid) return directions;
  const se3::Matrix6d from_centre = se3::adjoint(centre_pose(geometry));
  for (int k = 0; k < 6; ++k) {
    if (eigen.solver.eigenvalues()(k) >= min_eigenvalue_ratio * eigen.solver.eigenvalues()(5)) {
      break;  // ascending
    }
    const se3::Vector6d u = eigen.solver.eigenvectors().col(k);
    directions.push_back(from_centre * u.cwiseProduct(eigen.scale));
  }
  return directions;
}

double translation_constraint(const GeometricInformation& geometry,
                              const Eigen::Vector3d& direction) {
  const Eigen::Matrix3d translation = geometry.information.bottomRightCorner<3, 3>();
  const double largest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(translation).eigenvalues().maxCoeff();
  return largest > 0 ? direction.dot(translation * direction) / largest : 0.0;
}

std::vector<Eigen::Vector3d> free_translations(const GeometricInformation& geometry,
                                               double min_eigenvalue_ratio) {
  // The translation block is the same about the camera or the centroid (sums of n n^T).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(
      geometry.information.bottomRightCorner<3, 3>());
  std::vector<Eigen::Vector3d> free;
  const double largest = eigen.eigenvalues()(2);
  if (!(largest > 0)) return free;
  for (int k = 0; k < 3 && eigen.eigenvalues()(k) < min_eigenvalue_ratio * largest; ++k) {
    free.push_back(eigen.eigenvectors().col(k).normalized());  // ascending
  }
  return free;
}

se3::Matrix6d information_along(const se3::Matrix6d& information,
                                std::span<const se3::Vector6d> directions) {
  if (directions.empty()) return se3::Matrix6d::Zero();
  Eigen::Matrix<double, 6, Eigen::Dynamic> along(6, static_cast<Eigen::Index>(directions.size()));
  for (std::size_t k = 0; k < directions.size(); ++k) {
    along.col(static_cast<Eigen::Index>(k)) = directions[k];
  }
  // The amounts of a perturbation xi: along^+ xi.
  const Eigen::MatrixXd amounts = along.completeOrthogonalDecomposition().pseudoInverse();
  return amounts.transpose() * (along.transpose() * information * along) * amounts;
}

Eigen::Isometry3d keep_constrained_directions(const Eigen::Isometry3d& measured,
                                              const Eigen::Isometry3d& predicted,
                                              const GeometricInformation& geometry,
                                              double min_eigenvalue_ratio) {
  const BalancedEigen eigen = balanced_eigen(geometry);
  if (!eigen.valid) return predicted;  // nothing was constrained
  const double largest = eigen.solver.eigenvalues()(5);
  // The difference as a motion about the centre, T exp(delta) with delta = Ad(T(c)) xi_c, in
  // balanced coordinates y (xi_c = S y).
  const Eigen::Isometry3d to_centre = centre_pose(geometry);
  const se3::Vector6d delta = se3::log(measured.inverse() * predicted);
  const se3::Vector6d y = (se3::adjoint(to_centre.inverse()) * delta).cwiseQuotient(eigen.scale);
  se3::Vector6d weak = se3::Vector6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (eigen.solver.eigenvalues()(k) >= min_eigenvalue_ratio * largest) continue;
    const se3::Vector6d u = eigen.solver.eigenvectors().col(k);
    weak += u.dot(y) * u;
  }
  return measured * se3::exp(se3::adjoint(to_centre) * weak.cwiseProduct(eigen.scale));
}

}  // namespace kartograf::registration
