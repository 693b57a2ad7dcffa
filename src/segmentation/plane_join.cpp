// The second pass of plane merging (plane_merge.hpp): joins adjacent merged planes, cheapest pair
// first, and compacts the planes left.
#include "segmentation/plane_join.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <vector>

#include "compute/cpu_parallel.hpp"

namespace kartograf::segmentation::detail {

namespace {

using geometry::kNoLabel;

constexpr double kNoJoin = 2.0;  // the cost of a pair that must not join (any cost >= 1 is a no)

// Planes touch when segments of theirs are adjacent; they are near when both touch one unmerged
// segment (a gap left by the first pass must not keep two pieces of one plane apart).
enum Relation : std::uint8_t { apart = 0, near = 1, touching = 2 };

// Sign-free angle between unit normals at most max_deg (anything at 90 or more).
bool normals_within(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double max_deg) {
  return max_deg >= 90.0 || std::fabs(a.dot(b)) >= std::cos(max_deg * M_PI / 180.0);
}

// The Relation of every pair of merged planes, row-major over plane_count^2 (touching wins over
// near).
std::vector<std::uint8_t> plane_relations(const MergedPlanes& merged) {
  const SegmentGraph& graph = merged.graph;
  const std::size_t plane_count = merged.planes.size();
  std::vector<std::vector<std::uint32_t>> adjacent(plane_count), near_planes(plane_count);
  std::vector<std::uint32_t> around;
  for (std::uint32_t s = 0; s + 1 < graph.offsets.size(); ++s) {
    const std::uint32_t p = merged.segment_plane[s];
    around.clear();
    for (std::uint32_t k = graph.offsets[s]; k < graph.offsets[s + 1]; ++k) {
      const std::uint32_t q = merged.segment_plane[graph.neighbours[k]];
      if (q != kNoLabel && q != p) around.push_back(q);
    }
    if (p != kNoLabel) {
      adjacent[p].insert(adjacent[p].end(), around.begin(), around.end());
      continue;
    }
    for (const std::uint32_t a : around) {
      for (const std::uint32_t b : around) {
        if (a != b) near_planes[a].push_back(b);
      }
    }
  }
  std::vector<std::uint8_t> relation(plane_count * plane_count, apart);
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (const std::uint32_t q : near_planes[p])
      relation[p * plane_count + q] = relation[q * plane_count + p] = near;
  }
  for (std::uint32_t p = 0; p < plane_count; ++p) {
    for (const std::uint32_t q : adjacent[p])
      relation[p * plane_count + q] = relation[q * plane_count + p] = touching;
  }
  return relation;
}

// Angle tests are widened by each normal's uncertainty (see normal_uncertainty_deg). A pair
// passes when the angle between the normals is at most pair_angle + u_p + u_q: each plane keeps
// the cosine and sine of t_p = pair_angle / 2 + u_p, so that the pair's limit is
// cos(t_p + t_q) = cos t_p cos t_q - sin t_p sin t_q, with no trigonometry per pair.
struct AngleShare {
  double cos = 0, sin = 1;
};

// The join pass's state: the cached cost of every pair (upper triangle) and the cheapest pair of
// each row; a join re-evaluates the pairs of the joined plane. Planes absorbed into another are
// left with count 0 (and alias the plane they joined) until compact().
class PlaneJoiner {
 public:
  PlaneJoiner(const SegmentLabelImage& labels, const MergeInputs& inputs,
              const PlaneMergeParams& params, const Eigen::Vector3d& origin, MergedPlanes& merged);
  void join_cheapest_pairs();  // while some pair costs below 1
  void compact();              // drops absorbed planes, renumbers in order

 private:
  std::uint32_t plane_of_segment(std::uint32_t s) const;
  void sum_pixels();
  double see_through(std::uint32_t p, std::uint32_t q, const SegmentPlane& plane);
  void update_uncertainty(std::uint32_t p);
  void update_mean_colour(std::uint32_t p);
  bool pair_within(std::uint32_t p, std::uint32_t q, bool adjacent_pair) const;
  bool each_near_other_plane(std::uint32_t p, std::uint32_t q) const;
  double side_cost(std::uint32_t r, const SegmentPlane& own, const SegmentPlane& joint,
                   Relation relation) const;
  double fit_cost(std::uint32_t p, std::uint32_t q, const SegmentPlane& joint,
                  Relation relation) const;
  double cost_before_see_through(std::uint32_t p, std::uint32_t q, Relation relation,
                                 SegmentPlane& joint, bool& look) const;
  double cost(std::uint32_t p, std::uint32_t q, Relation relation);
  bool may_join(std::uint32_t lo, std::uint32_t hi, Relation relation) const;
  void evaluate(std::uint32_t p, std::uint32_t q);
  void evaluate_all_pairs();
  double cost_of(std::uint32_t p, std::uint32_t q) const;
  void update_row(std::uint32_t p);
  void absorb(std::uint32_t p, std::uint32_t q);
  void rejoin_pairs(std::uint32_t p, std::uint32_t q);

  const SegmentLabelImage& labels_;
  std::function<std::uint32_t(int, int)> segment_at_;  // the caller's, or the labels'
  const PointImage* points_;
  std::span<const Eigen::Vector3d> segment_pixel_sums_;  // per segment, or empty
  const PlaneMergeParams& params_;
  const Eigen::Vector3d& origin_;
  MergedPlanes& merged_;
  const std::size_t plane_count_;
  std::vector<std::uint32_t> alias_;  // an absorbed plane: the plane it joined
  // Pixel centroids (x, y sums and count) of the planes, for the see-through test: summed at
  // its first use (most frames have no pair that gets that far).
  std::vector<Eigen::Vector3d> pixel_sums_;
  std::vector<std::uint8_t> relation_;  // Relation per pair, row-major
  std::vector<double> uncertainty_;
  std::vector<Eigen::Vector3d> mean_colour_;      // per plane, when the planes have colours
  std::vector<std::array<AngleShare, 2>> share_;  // [0] touching/near, [1] apart
  std::vector<double> pair_cost_;                 // upper triangle, row-major
  // The cheapest pair of each row (q > p; the first of equal costs), so that finding the next
  // join scans rows, not pairs.
  std::vector<std::uint32_t> row_best_;
};

PlaneJoiner::PlaneJoiner(const SegmentLabelImage& labels, const MergeInputs& inputs,
                         const PlaneMergeParams& params, const Eigen::Vector3d& origin,
                         MergedPlanes& merged)
    : labels_(labels),
      segment_at_(inputs.segment_at ? inputs.segment_at
                                    : [&labels](int x, int y) { return labels(x, y); }),
      points_(inputs.points),
      segment_pixel_sums_(inputs.pixel_sums),
      params_(params),
      origin_(origin),
      merged_(merged),
      plane_count_(merged.planes.size()),
      alias_(plane_count_),
      relation_(plane_relations(merged)),
      uncertainty_(plane_count_),
      share_(plane_count_),
      pair_cost_(plane_count_ * plane_count_, kNoJoin),
      row_best_(plane_count_, kNoLabel) {
  std::iota(alias_.begin(), alias_.end(), 0u);
  if (!merged_.colour_sums.empty()) mean_colour_.resize(plane_count_);
  for (std::uint32_t p = 0; p < plane_count_; ++p) update_uncertainty(p), update_mean_colour(p);
  evaluate_all_pairs();
  for (std::uint32_t p = 0; p < plane_count_; ++p) update_row(p);
}

std::uint32_t PlaneJoiner::plane_of_segment(std::uint32_t s) const {
  std::uint32_t p = merged_.segment_plane[s];
  if (p == kNoLabel) return p;
  while (alias_[p] != p) p = alias_[p];
  return p;
}

// Each segment's pixels in the labels (sum of x, sum of y, count), run by run along the rows.
std::vector<Eigen::Vector3d> label_pixel_sums(const SegmentLabelImage& labels,
                                              std::size_t segment_count) {
  std::vector<Eigen::Vector3d> sums(segment_count, Eigen::Vector3d::Zero());
  const int width = labels.width();
  for (int y = 0; y < labels.height(); ++y) {
    const std::uint32_t* row = &labels(0, y);
    for (int x = 0; x < width;) {
      const std::uint32_t s = row[x];
      int end = x + 1;
      while (end < width && row[end] == s) ++end;
      if (s != kNoLabel) {
        const std::int64_t n = end - x;
        sums[s] += Eigen::Vector3d(static_cast<double>(n * (x + end - 1) / 2),
                                   static_cast<double>(n * y), static_cast<double>(n));
      }
      x = end;
    }
  }
  return sums;
}

// Integers in double: the sums are exact in any order.
void PlaneJoiner::sum_pixels() {
  pixel_sums_.assign(plane_count_, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> from_labels;
  std::span<const Eigen::Vector3d> segment_sums = segment_pixel_sums_;  // the caller's, if given
  if (segment_sums.empty()) {
    from_labels = label_pixel_sums(labels_, merged_.segment_plane.size());
    segment_sums = from_labels;
  }
  for (std::uint32_t s = 0; s < segment_sums.size(); ++s) {
    const std::uint32_t p = plane_of_segment(s);
    if (p != kNoLabel) pixel_sums_[p] += segment_sums[s];
  }
}

// Fraction of the valid pixels on the image line between the pixel centroids of p and q, other
// than theirs, where the camera sees through `plane` (the point lies behind it by more than the
// allowance): evidence that the plane does not continue between the two pieces.
double PlaneJoiner::see_through(std::uint32_t p, std::uint32_t q, const SegmentPlane& plane) {
  if (pixel_sums_.empty()) sum_pixels();
  const Eigen::Vector2d from = pixel_sums_[p].head<2>() / pixel_sums_[p].z();
  const Eigen::Vector2d to = pixel_sums_[q].head<2>() / pixel_sums_[q].z();
  const int steps = static_cast<int>(std::ceil((to - from).cwiseAbs().maxCoeff()));
  int valid = 0, behind = 0;
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector2d at = from + (to - from) * (steps > 0 ? double(k) / steps : 0.0);
    const int x = static_cast<int>(std::lround(at.x())), y = static_cast<int>(std::lround(at.y()));
    const std::uint32_t s = segment_at_(x, y);
    const std::uint32_t owner = s == kNoLabel ? kNoLabel : plane_of_segment(s);
    const Point4f& point = (*points_)(x, y);
    if (owner == p || owner == q || !is_valid(point)) continue;
    const Eigen::Vector3d ray = point.head<3>().cast<double>();
    ++valid;
    const double along = plane.normal.dot(ray);
    if (along == 0.0) continue;
    const double scale = -plane.offset / along;  // the plane's point on this ray: scale * ray
    if (scale > 0.0 && (1.0 - scale) * ray.norm() > allowance(params_, ray, plane)) ++behind;
  }
  return valid == 0 ? 0.0 : static_cast<double>(behind) / valid;
}

void PlaneJoiner::update_uncertainty(std::uint32_t p) {
  uncertainty_[p] =
      merged_.planes[p].valid ? normal_uncertainty_deg(params_, merged_.planes[p]) : 90.0;
  for (int k = 0; k < 2; ++k) {
    const double half = 0.5 * (k == 0 ? params_.max_normal_angle_deg : params_.max_apart_angle_deg);
    const double t = std::min(90.0, half + uncertainty_[p]) * M_PI / 180.0;
    share_[p][k] = {std::cos(t), std::sin(t)};
  }
}

// Each pair's colour test reads the means: kept per plane, not divided out for every pair.
void PlaneJoiner::update_mean_colour(std::uint32_t p) {
  if (!mean_colour_.empty())
    mean_colour_[p] = merged_.colour_sums[p] / static_cast<double>(merged_.planes[p].count);
}

bool PlaneJoiner::pair_within(std::uint32_t p, std::uint32_t q, bool adjacent_pair) const {
  const AngleShare& a = share_[p][adjacent_pair ? 0 : 1];
  const AngleShare& b = share_[q][adjacent_pair ? 0 : 1];
  const double limit = a.cos * b.cos - a.sin * b.sin;  // cos(t_p + t_q); <= 0 beyond 90 deg
  return limit <= 0.0 || std::fabs(merged_.planes[p].normal.dot(merged_.planes[q].normal)) >= limit;
}

// The cheap necessary test of planes apart: each side near the other's plane.
bool PlaneJoiner::each_near_other_plane(std::uint32_t p, std::uint32_t q) const {
  const SegmentPlane& a = merged_.planes[p];
  const SegmentPlane& b = merged_.planes[q];
  const double limit_a = allowance(params_, a.centroid, b),
               limit_b = allowance(params_, b.centroid, a);
  return !(mean_squared_distance(merged_.moments[q], origin_, a.normal, a.offset) >
               4.0 * limit_b * limit_b ||
           mean_squared_distance(merged_.moments[p], origin_, b.normal, b.offset) >
               4.0 * limit_a * limit_a);
}

// One side's cost: its RMS distance to the joint plane over the allowance at its own depth (so a
// far noisy surface cannot drag a near one along), or its centroid's offset from it.
double PlaneJoiner::side_cost(std::uint32_t r, const SegmentPlane& own, const SegmentPlane& joint,
                              Relation relation) const {
  const double limit = allowance(params_, own.centroid, joint);
  const double rms =
      std::sqrt(mean_squared_distance(merged_.moments[r], origin_, joint.normal, joint.offset));
  const double shift = std::fabs(joint.normal.dot(own.centroid) + joint.offset);
  // The base term is for sensor bending within one continuous surface, not across a gap.
  return std::max(rms / limit, shift / offset_allowance(params_, own.centroid, joint.normal,
                                                        relation == touching));
}

// The cost of the joint fit of p and q: the worst of its RMS over the allowance, its RMS growth
// over the parts' own fits, and each side's cost.
double PlaneJoiner::fit_cost(std::uint32_t p, std::uint32_t q, const SegmentPlane& joint,
                             Relation relation) const {
  const SegmentPlane& a = merged_.planes[p];
  const SegmentPlane& b = merged_.planes[q];
  // The joint fit may be worse than the parts' own fits only by depth noise: a step or a crease
  // between two well-fitted pieces shows here even when it hides within the allowance.
  const double own_ms = (static_cast<double>(a.count) * a.rms_error * a.rms_error +
                         static_cast<double>(b.count) * b.rms_error * b.rms_error) /
                        static_cast<double>(a.count + b.count);
  const double joint_limit = std::max(params_.max_joint_rms_growth * std::sqrt(own_ms),
                                      depth_noise(params_, joint.centroid, joint.normal));
  return std::max({joint.rms_error / allowance(params_, joint.centroid, joint),
                   joint.rms_error / joint_limit, side_cost(p, a, joint, relation),
                   side_cost(q, b, joint, relation)});
}

// Cost of joining p and q (>= 1: no). Each side must lie within the allowance at its own depth
// of the joint plane. Pairs that are not near (a plane cut in two by an occluder or a doorway)
// must also be nearly parallel. `look`: whether the see-through test must still pass, on `joint`.
double PlaneJoiner::cost_before_see_through(std::uint32_t p, std::uint32_t q, Relation relation,
                                            SegmentPlane& joint, bool& look) const {
  look = false;
  const bool adjacent_pair = relation != apart;
  const SegmentPlane& a = merged_.planes[p];
  const SegmentPlane& b = merged_.planes[q];
  if (!a.valid || !b.valid) return kNoJoin;
  // The cheap tests first (most pairs are apart and fail one of them).
  const bool coloured = !mean_colour_.empty();
  const double colour_distance_sq =
      coloured ? (mean_colour_[p] - mean_colour_[q]).squaredNorm() : 0.0;
  if (!adjacent_pair &&
      colour_distance_sq > params_.max_apart_colour_distance * params_.max_apart_colour_distance) {
    return kNoJoin;
  }
  if (!pair_within(p, q, adjacent_pair)) return kNoJoin;
  if (!adjacent_pair && !each_near_other_plane(p, q)) return kNoJoin;
  geometry::SegmentMoments both = merged_.moments[p];
  both += merged_.moments[q];
  joint = fit_plane(both, origin_, params_.fit);
  // Two parallel pieces with a step between them fit a plane tilted to both: the joint plane
  // itself must keep within the angle of each.
  if (!joint.valid ||
      !normals_within(joint.normal, a.normal, params_.max_normal_angle_deg + uncertainty_[p]) ||
      !normals_within(joint.normal, b.normal, params_.max_normal_angle_deg + uncertainty_[q])) {
    return kNoJoin;
  }
  const double result = fit_cost(p, q, joint, relation);
  // Seen through the gap: one wall on both sides of a doorway, or two coplanar objects.
  look = result < 1.0 && !adjacent_pair && points_ != nullptr &&
         (!coloured || colour_distance_sq > params_.max_see_through_colour_distance *
                                                params_.max_see_through_colour_distance);
  return result;
}

double PlaneJoiner::cost(std::uint32_t p, std::uint32_t q, Relation relation) {
  SegmentPlane joint;
  bool look = false;
  const double result = cost_before_see_through(p, q, relation, joint, look);
  if (look && see_through(p, q, joint) > params_.max_see_through_fraction) return kNoJoin;
  return result;
}

bool PlaneJoiner::may_join(std::uint32_t lo, std::uint32_t hi, Relation relation) const {
  return relation != apart ||
         (params_.join_apart && merged_.moments[lo].count >= params_.min_apart_pixels &&
          merged_.moments[hi].count >= params_.min_apart_pixels);
}

void PlaneJoiner::evaluate(std::uint32_t p, std::uint32_t q) {
  const std::uint32_t lo = std::min(p, q), hi = std::max(p, q);
  const auto relation = static_cast<Relation>(relation_[lo * plane_count_ + hi]);
  pair_cost_[lo * plane_count_ + hi] =
      may_join(lo, hi, relation) ? cost(lo, hi, relation) : kNoJoin;
}

// Every pair's cost, the pairs over the CPU threads (cost_before_see_through reads only what the
// pass has not changed yet), then the see-through tests on this thread (the first one sums
// the planes' pixels). The same costs as evaluate() pair by pair.
void PlaneJoiner::evaluate_all_pairs() {
  struct Deferred {
    std::uint32_t p, q;
    SegmentPlane joint;
  };
  const std::size_t n = plane_count_;
  std::array<std::vector<Deferred>, compute::detail::kCpuChunks> deferred;
  // Rows in the order 0, n - 1, 1, n - 2, ...: neighbouring rows hold n - 1 pairs together, so
  // that contiguous chunks of rows hold alike numbers of pairs. A pair's tests cost about what
  // kPairWork points do.
  constexpr std::size_t kPairWork = 8;
  compute::detail::for_each_chunk(
      n, n * n / 2 * kPairWork, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
        for (std::size_t k = begin; k < end; ++k) {
          const auto p = static_cast<std::uint32_t>(k % 2 == 0 ? k / 2 : n - 1 - k / 2);
          for (std::uint32_t q = p + 1; q < n; ++q) {
            const auto relation = static_cast<Relation>(relation_[p * n + q]);
            SegmentPlane joint;
            bool look = false;
            pair_cost_[p * n + q] = may_join(p, q, relation)
                                        ? cost_before_see_through(p, q, relation, joint, look)
                                        : kNoJoin;
            if (look) deferred[chunk].push_back({p, q, joint});
          }
        }
      });
  for (const std::vector<Deferred>& chunk : deferred) {
    for (const Deferred& pair : chunk) {
      if (see_through(pair.p, pair.q, pair.joint) > params_.max_see_through_fraction)
        pair_cost_[pair.p * n + pair.q] = kNoJoin;
    }
  }
}

double PlaneJoiner::cost_of(std::uint32_t p, std::uint32_t q) const {
  return q == kNoLabel ? kNoJoin : pair_cost_[p * plane_count_ + q];
}

void PlaneJoiner::update_row(std::uint32_t p) {
  row_best_[p] = kNoLabel;
  for (std::uint32_t q = p + 1; q < plane_count_; ++q) {
    if (pair_cost_[p * plane_count_ + q] < cost_of(p, row_best_[p])) row_best_[p] = q;
  }
}

// q joins p: moments, colour, fit and pixel sums.
void PlaneJoiner::absorb(std::uint32_t p, std::uint32_t q) {
  merged_.moments[p] += merged_.moments[q];
  merged_.moments[q] = {};
  if (!merged_.colour_sums.empty()) merged_.colour_sums[p] += merged_.colour_sums[q];
  merged_.planes[p] = fit_plane(merged_.moments[p], origin_, params_.fit);
  merged_.planes[q] = {};
  if (!pixel_sums_.empty()) pixel_sums_[p] += pixel_sums_[q];
  update_uncertainty(p);
  update_mean_colour(p);
  alias_[q] = p;
}

// After q joined p: p takes q's relations, q's costs are dropped, p's are re-evaluated, and the
// rows' cheapest pairs follow.
void PlaneJoiner::rejoin_pairs(std::uint32_t p, std::uint32_t q) {
  for (std::uint32_t r = 0; r < plane_count_; ++r) {
    const std::uint8_t relation =
        std::max(relation_[p * plane_count_ + r], relation_[q * plane_count_ + r]);
    relation_[p * plane_count_ + r] = relation_[r * plane_count_ + p] = relation;
    const std::uint32_t lo = std::min(r, q), hi = std::max(r, q);
    pair_cost_[lo * plane_count_ + hi] = kNoJoin;
  }
  relation_[p * plane_count_ + p] = apart;
  for (std::uint32_t r = 0; r < plane_count_; ++r) {
    if (r != p && merged_.moments[r].count > 0) evaluate(p, r);
  }
  // Rows whose cheapest pair involved p or q start over; the others compare with (r, p).
  for (std::uint32_t r = 0; r < plane_count_; ++r) {
    if (r == p || row_best_[r] == p || row_best_[r] == q) {
      update_row(r);
    } else if (r < p) {
      const double changed = pair_cost_[r * plane_count_ + p];
      const double current = cost_of(r, row_best_[r]);
      if (changed < current || (changed == current && p < row_best_[r])) row_best_[r] = p;
    }
  }
  row_best_[q] = kNoLabel;
}

void PlaneJoiner::join_cheapest_pairs() {
  for (;;) {
    double best = 1.0;
    std::uint32_t best_p = kNoLabel, best_q = kNoLabel;
    for (std::uint32_t p = 0; p < plane_count_; ++p) {
      if (cost_of(p, row_best_[p]) < best)
        best = cost_of(p, row_best_[p]), best_p = p, best_q = row_best_[p];
    }
    if (best_p == kNoLabel) break;
    absorb(best_p, best_q);
    rejoin_pairs(best_p, best_q);
  }
}

void PlaneJoiner::compact() {
  std::vector<std::uint32_t> renumber(plane_count_, kNoLabel);
  MergedPlanes compact;
  for (std::uint32_t p = 0; p < plane_count_; ++p) {
    if (merged_.moments[p].count == 0) continue;
    renumber[p] = static_cast<std::uint32_t>(compact.planes.size());
    compact.planes.push_back(merged_.planes[p]);
    compact.moments.push_back(merged_.moments[p]);
    if (!merged_.colour_sums.empty()) compact.colour_sums.push_back(merged_.colour_sums[p]);
  }
  compact.segment_plane = std::move(merged_.segment_plane);
  compact.graph = merged_.graph;
  for (std::uint32_t& p : compact.segment_plane) {
    if (p == kNoLabel) continue;
    while (alias_[p] != p) p = alias_[p];
    p = renumber[p];
  }
  merged_ = std::move(compact);
}

}  // namespace

void join_adjacent_planes(const SegmentLabelImage& labels, const MergeInputs& inputs,
                          const PlaneMergeParams& params, const Eigen::Vector3d& origin,
                          MergedPlanes& merged) {
  PlaneJoiner joiner(labels, inputs, params, origin, merged);
  joiner.join_cheapest_pairs();
  joiner.compact();
}

}  // namespace kartograf::segmentation::detail
