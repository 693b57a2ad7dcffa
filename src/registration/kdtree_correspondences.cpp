#include "kartograf/registration/kdtree_correspondences.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <nanoflann.hpp>

#include "registration/nearest_neighbor.hpp"

namespace kartograf::registration {

bool NormalGate::accepts(std::size_t j) const {
  const Point4f& n = normals[j];
  return kernels::nearest_normal_accepts({normal.x(), normal.y(), normal.z()},
                                         {n.x(), n.y(), n.z(), n.w()}, min_cosine);
}

namespace {

// nanoflann's view of the tree's points, in double (so distances are the shared rule's doubles).
struct PointsAdaptor {
  const std::vector<Point4f>* points;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::uint32_t index, std::size_t dim) const { return (*points)[index][dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox&) const {
    return false;  // let nanoflann compute it
  }
};

using Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointsAdaptor, double>,
                                        PointsAdaptor, 3, std::uint32_t>;

// A nanoflann result set that keeps the shared rule's best candidate: nanoflann offers leaf points
// closer than worstDist(), so reporting the bound one ulp up lets equally near points and points
// exactly at max_distance through to the tie-break.
class NearestResult {
 public:
  using DistanceType = double;
  using IndexType = std::uint32_t;

  NearestResult(double max_distance_sq, const std::vector<std::int32_t>& original,
                const NormalGate* gate)
      : best_(max_distance_sq), original_(original), gate_(gate) {}

  bool full() const { return true; }
  double worstDist() const {
    return std::nextafter(best_.distance_sq, std::numeric_limits<double>::infinity());
  }
  bool addPoint(double distance_sq, std::uint32_t index) {
    const std::int32_t j = original_[index];
    if (best_.improves(j, distance_sq) && (!gate_ || gate_->accepts(static_cast<std::size_t>(j)))) {
      best_.take(j, distance_sq);
    }
    return true;
  }
  std::int32_t index() const { return best_.index; }

 private:
  detail::Nearest best_;
  const std::vector<std::int32_t>& original_;
  const NormalGate* gate_;
};

}  // namespace

struct KdTree::Index {
  std::vector<Point4f> points;         // the valid points
  std::vector<std::int32_t> original;  // their indices in the input cloud
  PointsAdaptor adaptor{&points};
  std::unique_ptr<Tree> tree;
  float eps = 0;
};

KdTree::KdTree(std::span<const Point4f> points, KdTreeParams params)
    : index_(std::make_unique<Index>()) {
  require(params.leaf_size >= 1,
          "k-d tree: leaf_size must be >= 1, got " + std::to_string(params.leaf_size));
  require(std::isfinite(params.eps) && params.eps >= 0, "k-d tree: eps must be finite and >= 0");
  require(points.size() < (std::size_t{1} << 31), "k-d tree: more than 2^31 points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!is_valid(points[i])) continue;
    index_->points.push_back(points[i]);
    index_->original.push_back(static_cast<std::int32_t>(i));
  }
  index_->eps = params.eps;
  index_->tree = std::make_unique<Tree>(
      3, index_->adaptor,
      nanoflann::KDTreeSingleIndexAdaptorParams(static_cast<std::size_t>(params.leaf_size)));
}

KdTree::KdTree(KdTree&&) noexcept = default;
KdTree& KdTree::operator=(KdTree&&) noexcept = default;
KdTree::~KdTree() = default;

std::size_t KdTree::size() const {
  return index_->points.size();
}

std::int32_t KdTree::nearest(const Eigen::Vector3d& query, double max_distance_sq,
                             const NormalGate* gate) const {
  if (index_->points.empty() || !(max_distance_sq >= 0)) return kNoMatch;
  NearestResult result(max_distance_sq, index_->original, gate);
  const double point[3] = {query.x(), query.y(), query.z()};
  index_->tree->findNeighbors(result, point, nanoflann::SearchParams(32, index_->eps));
  return result.index();
}

KdTreeCorrespondences::KdTreeCorrespondences(const compute::Context& context, KdTreeParams params)
    : context_(&context), params_(params) {
  require(params.leaf_size >= 1 && std::isfinite(params.eps) && params.eps >= 0,
          "k-d tree correspondences: leaf_size must be >= 1 and eps >= 0");
}

void KdTreeCorrespondences::build(const CloudView& target) {
  require(target.points != nullptr, "k-d tree correspondences: target points are required");
  tree_.emplace(compute::read_on_host(*target.points), params_);
  built_for_ = target.points;
  target_normals_.reset();
  if (target.normals) target_normals_.emplace(*target.normals);
}

void KdTreeCorrespondences::prepare(const CloudView& target, int) {
  build(target);
}

void KdTreeCorrespondences::find(const CloudView& source, const CloudView& target,
                                 const Eigen::Isometry3d& source_to_target,
                                 const AssociationParams& params, CorrespondenceBuffers& out) {
  const detail::NearestQuery query = detail::make_query(source_to_target, params);
  detail::validate(source, target, params, query.use_normals, "k-d tree correspondences");
  require(source_to_target.matrix().allFinite(),
          "k-d tree correspondences: the pose has NaN/Inf entries");
  if (!tree_ || built_for_ != target.points) build(target);
  if (out.target_index.size() != source.size()) {
    out.target_index = compute::Buffer<std::int32_t>(*context_, source.size());
  }
  if (source.size() == 0) return;

  // A host-only search: the views are free on the CPU backend, copies from other devices.
  const compute::Buffer<Point4f> absent;
  const auto source_points = compute::read_on_host(*source.points);
  const auto source_normals = compute::read_on_host(query.use_normals ? *source.normals : absent);
  if (query.use_normals && !target_normals_) target_normals_.emplace(*target.normals);
  const std::span<const Point4f> target_normals =
      query.use_normals ? target_normals_->span() : std::span<const Point4f>();
  auto result = compute::write_on_host(out.target_index, compute::HostWriteStart::overwrite_all);
  const auto width = source.camera ? static_cast<std::uint32_t>(source.camera->width) : 0u;
  const double max_distance_sq = query.max_distance_sq();
  detail::find_each(query, source_points, source_normals, target_normals, width,
                    static_cast<std::uint32_t>(params.subsample), result,
                    [&](const Eigen::Vector3d& moved, const NormalGate* gate) {
                      return tree_->nearest(moved, max_distance_sq, gate);
                    });
  result.commit();
}

}  // namespace kartograf::registration
