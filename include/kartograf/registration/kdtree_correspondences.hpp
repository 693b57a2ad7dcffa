#pragma once
// Nearest-neighbour correspondences for unorganized clouds with a k-d tree
// (docs/methods.md M3 step 2; the paper used ANN, this uses nanoflann): the tree is built once per
// target cloud on the host and queried with the moved source points. CPU only; on a device context
// the finder downloads the clouds and uploads the correspondences (voxel_hash_correspondences.hpp
// searches on the device).
//
// Rules, shared with VoxelHashCorrespondences (identical results): for source point i,
// not is_selected(i, source width or 0, subsample) -> kNotSelected; an invalid p (or, with the
// normal gate on, an invalid n_p) -> kNoMatch; otherwise p' = R p + t and the partner is the
// valid target point q nearest to p' with |p' - q|^2 <= max_distance^2 — and, with the normal
// gate on (max_normal_angle_deg < 180), whose normal n_q is valid with
// (R n_p) . n_q >= cos(max_normal_angle_deg) — the lowest index among equally near ones; kNoMatch
// when there is none. Moved points and squared distances are computed in double in a fixed order
// ((dx dx + dy dy) + dz dz), without contraction, on every backend.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "kartograf/compute/buffer.hpp"
#include "kartograf/core/point_image.hpp"
#include "kartograf/registration/correspondence_finder.hpp"

namespace kartograf::registration {

// The normal gate of one query: candidate j qualifies when normals[j] is valid and
// normal . normals[j] >= min_cosine (normal: the source normal rotated into the target frame).
struct NormalGate {
  std::span<const Point4f> normals;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double min_cosine = -1;

  // Target normal j valid and normal . n_j >= min_cosine: the voxel-hash search's gate
  // (kernels/voxel_hash_nearest/voxel_hash_nearest.h), one rule for both.
  bool accepts(std::size_t j) const;
};

struct KdTreeParams {
  int leaf_size = 10;  // points per leaf
  // Approximate search (ANN's error bound): a returned point is at most (1 + eps) times farther
  // than the true nearest one, in squared distance. 0: exact.
  float eps = 0;
};

// A k-d tree over the valid points of a cloud (a copy: the cloud may change afterwards).
class KdTree {
 public:
  // Throws Error for leaf_size < 1 or eps < 0.
  explicit KdTree(std::span<const Point4f> points, KdTreeParams params = {});
  KdTree(KdTree&&) noexcept;
  KdTree& operator=(KdTree&&) noexcept;
  ~KdTree();

  // The index (into the original cloud) of the nearest valid point q with
  // |query - q|^2 <= max_distance_sq that the gate (if any) accepts, the lowest index among
  // equally near ones; kNoMatch when there is none.
  std::int32_t nearest(const Eigen::Vector3d& query, double max_distance_sq,
                       const NormalGate* gate = nullptr) const;
  std::size_t size() const;  // valid points in the tree

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

// The CorrespondenceFinder of the ICP engine over a k-d tree of the target (see the rules above).
class KdTreeCorrespondences : public CorrespondenceFinder {
 public:
  explicit KdTreeCorrespondences(const compute::Context& context, KdTreeParams params = {});

  // Builds the tree of target (downloading its points, and normals, from a device).
  void prepare(const CloudView& target, int level) override;
  // Also builds it when prepare() was not called for this target buffer.
  void find(const CloudView& source, const CloudView& target,
            const Eigen::Isometry3d& source_to_target, const AssociationParams& params,
            CorrespondenceBuffers& out) override;

 private:
  void build(const CloudView& target);

  const compute::Context* context_;
  KdTreeParams params_;
  std::optional<KdTree> tree_;
  const compute::Buffer<Point4f>* built_for_ = nullptr;
  // The target's normals on the host for the normal gate: the buffer itself on the CPU backend,
  // else downloaded once per build, not once per ICP iteration.
  std::optional<compute::HostView<Point4f>> target_normals_;
};

}  // namespace kartograf::registration
