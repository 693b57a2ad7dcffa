#include "kartograf/semantic/regions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include <Eigen/Eigenvalues>

#include "kartograf/core/error.hpp"

namespace kartograf::semantic {
namespace {

double cos_deg(double degrees) {
  return std::cos(degrees * std::numbers::pi / 180.0);
}

Eigen::Vector3d vec3(const Point4f& p) {
  return p.head<3>().cast<double>();
}

bool ranges_continuous(const Point4f& a, const Point4f& b, double max_relative_jump) {
  const double ra = a.head<3>().norm(), rb = b.head<3>().norm();
  return std::fabs(ra - rb) <= max_relative_jump * std::min(ra, rb);
}

// Value at `fraction` of the sorted values (nearest rank), for trimmed extremes.
double quantile(std::vector<double>& values, double fraction) {
  const auto k = static_cast<std::size_t>(
      std::clamp(std::lround(fraction * static_cast<double>(values.size() - 1)), 0L,
                 static_cast<long>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double trimmed_extent(std::vector<double> values, double trim, double& low, double& high) {
  low = quantile(values, trim);
  high = quantile(values, 1.0 - trim);
  return high - low;
}

// The 4 neighbours of pixel i across gaps: in each direction the first pixel that is `usable`
// within 1 + max_gap steps (-1 where there is none). Dark surfaces return depth on a sparse subset
// of pixels (a dark door leaf under a structured-light sensor); without bridging, such a subset
// does not percolate through 4-neighbours and never forms a region.
template <typename Usable>
std::array<int, 4> gap_neighbours(int w, int h, int i, int max_gap, const Usable& usable) {
  const int x = i % w, y = i / w;
  constexpr int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  std::array<int, 4> out{-1, -1, -1, -1};
  for (int d = 0; d < 4; ++d) {
    for (int step = 1; step <= 1 + max_gap; ++step) {
      const int u = x + step * dx[d], v = y + step * dy[d];
      if (u < 0 || v < 0 || u >= w || v >= h) break;
      if (usable(v * w + u)) {
        out[static_cast<std::size_t>(d)] = v * w + u;
        break;
      }
    }
  }
  return out;
}

// Point moments (offsets from a common origin) of a set of points, for the plane they span.
struct PlaneMoments {
  double count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();

  void add(const Eigen::Vector3d& offset) {
    count += 1;
    sum += offset;
    outer += offset * offset.transpose();
  }
  void add(const PlaneMoments& other) {
    count += other.count;
    sum += other.sum;
    outer += other.outer;
  }
  Eigen::Vector3d centroid() const { return sum / count; }
  // Eigenvalues ascending: the first eigenvector is the plane's normal.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca() const {
    const Eigen::Vector3d c = centroid();
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(outer / count - c * c.transpose());
  }
  Eigen::Vector3d normal() const { return pca().eigenvectors().col(0); }
};

// Whether each region's points span a plane (PCA: smallest spread well below the middle one) whose
// normal agrees with the region's mean normal (see regions.hpp).
std::vector<bool> consistent_planes(const PointImage& points, const NormalImage& normals,
                                    const std::vector<int>& region_of,
                                    const std::vector<int>& sizes, const RegionParams& params) {
  const std::size_t n = sizes.size();
  std::vector<PlaneMoments> moments(n);
  std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero()), origin(n);
  std::vector<bool> seen(n, false);
  for (std::size_t i = 0; i < region_of.size(); ++i) {
    const int r = region_of[i];
    if (r < 0 || sizes[static_cast<std::size_t>(r)] < params.min_region_pixels) continue;
    const auto k = static_cast<std::size_t>(r);
    const Eigen::Vector3d p = vec3(points.pixels()[i]);
    if (!seen[k])
      origin[k] = p, seen[k] = true;  // offsets from a member keep sums well-conditioned
    moments[k].add(p - origin[k]);
    normal[k] += vec3(normals.pixels()[i]);
  }
  std::vector<bool> planar(n, false);
  const double region_cos = cos_deg(params.max_region_angle_deg);
  for (std::size_t k = 0; k < n; ++k) {
    if (!seen[k]) continue;
    const auto pca = moments[k].pca();
    const Eigen::Vector3d spread = pca.eigenvalues();  // ascending
    planar[k] = spread(0) * params.min_plane_spread_ratio <= spread(1) &&
                std::fabs(pca.eigenvectors().col(0).dot(normal[k].normalized())) >= region_cos;
  }
  return planar;
}

// The fill described in regions.hpp.
void fill_from_planes(const PointImage& points, const NormalImage& normals,
                      const RegionParams& params, RegionSegmentation& out) {
  const int w = points.width(), h = points.height();
  const auto n = static_cast<std::size_t>(out.region_count);
  std::vector<Eigen::Vector3d> centroid(n, Eigen::Vector3d::Zero()),
      normal(n, Eigen::Vector3d::Zero());
  std::vector<int> count(n, 0);
  std::vector<int> queue;
  for (int i = 0; i < w * h; ++i) {
    const Label l = out.labels.pixels()[static_cast<std::size_t>(i)];
    if (l == kUnlabeled) continue;
    centroid[l - 1u] += vec3(points.pixels()[static_cast<std::size_t>(i)]);
    normal[l - 1u] += vec3(normals.pixels()[static_cast<std::size_t>(i)]);
    ++count[l - 1u];
    queue.push_back(i);
  }
  for (std::size_t r = 0; r < n; ++r) {
    centroid[r] /= count[r];
    normal[r].normalize();
  }
  auto has_point = [&](int i) { return is_valid(points.pixels()[static_cast<std::size_t>(i)]); };
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int i = queue[head];
    const Label l = out.labels.pixels()[static_cast<std::size_t>(i)];
    const Point4f& p = points.pixels()[static_cast<std::size_t>(i)];
    for (const int j : gap_neighbours(w, h, i, params.max_gap_pixels, has_point)) {
      if (j < 0 || out.labels.pixels()[static_cast<std::size_t>(j)] != kUnlabeled) continue;
      const Point4f& q = points.pixels()[static_cast<std::size_t>(j)];
      if (!is_valid(q) || !ranges_continuous(p, q, params.max_relative_range_jump)) continue;
      const double distance = std::fabs(normal[l - 1u].dot(vec3(q) - centroid[l - 1u]));
      const double range = q.head<3>().norm();
      if (distance >
          params.fill_plane_distance +
              range * (params.fill_relative_distance + params.fill_quadratic_distance * range)) {
        continue;
      }
      out.labels.pixels()[static_cast<std::size_t>(j)] = l;
      queue.push_back(j);
    }
  }
}

}  // namespace

RegionSegmentation segment_regions(const PointImage& points, const NormalImage& normals,
                                   const RegionParams& params) {
  require(points.width() == normals.width() && points.height() == normals.height(),
          "segment_regions: points are " + std::to_string(points.width()) + "x" +
              std::to_string(points.height()) + " but normals " + std::to_string(normals.width()) +
              "x" + std::to_string(normals.height()));
  require(params.max_neighbour_angle_deg > 0 && params.max_neighbour_angle_deg < 180 &&
              params.max_region_angle_deg > 0 && params.max_region_angle_deg < 180,
          "segment_regions: angles must be in (0, 180) degrees");
  require(params.max_relative_range_jump > 0,
          "segment_regions: max_relative_range_jump must be > 0");
  require(params.min_region_pixels >= 1, "segment_regions: min_region_pixels must be >= 1");
  require(params.max_gap_pixels >= 0, "segment_regions: max_gap_pixels must be >= 0");

  const int w = points.width(), h = points.height();
  const double neighbour_cos = cos_deg(params.max_neighbour_angle_deg);
  const double region_cos = cos_deg(params.max_region_angle_deg);
  constexpr int kUnvisited = -1;
  std::vector<int> region_of(points.size(), kUnvisited);
  std::vector<int> sizes;
  std::vector<int> queue;
  auto usable = [&](int i) {
    return is_valid(points.pixels()[static_cast<std::size_t>(i)]) &&
           is_valid(normals.pixels()[static_cast<std::size_t>(i)]);
  };
  for (int seed = 0; seed < w * h; ++seed) {
    if (region_of[static_cast<std::size_t>(seed)] != kUnvisited || !usable(seed)) continue;
    const int region = static_cast<int>(sizes.size());
    Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
    queue.assign(1, seed);
    region_of[static_cast<std::size_t>(seed)] = region;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const int i = queue[head];
      const Point4f& p = points.pixels()[static_cast<std::size_t>(i)];
      const Eigen::Vector3d n = vec3(normals.pixels()[static_cast<std::size_t>(i)]);
      normal_sum += n;
      const Eigen::Vector3d mean = normal_sum.normalized();
      for (const int j : gap_neighbours(w, h, i, params.max_gap_pixels, usable)) {
        if (j < 0 || region_of[static_cast<std::size_t>(j)] != kUnvisited || !usable(j)) continue;
        const Eigen::Vector3d m = vec3(normals.pixels()[static_cast<std::size_t>(j)]);
        if (m.dot(n) < neighbour_cos || m.dot(mean) < region_cos ||
            !ranges_continuous(p, points.pixels()[static_cast<std::size_t>(j)],
                               params.max_relative_range_jump)) {
          continue;
        }
        region_of[static_cast<std::size_t>(j)] = region;
        queue.push_back(j);
      }
    }
    sizes.push_back(static_cast<int>(queue.size()));
    // Pixels refused here may seed or join other regions later: unmark nothing, they were never
    // marked. Small regions are dropped after all are grown.
  }
  RegionSegmentation out;
  out.labels = LabelImage(w, h, kUnlabeled);
  std::vector<Label> relabel(sizes.size(), kUnlabeled);
  const std::vector<bool> planar = consistent_planes(points, normals, region_of, sizes, params);
  for (std::size_t r = 0; r < sizes.size(); ++r) {
    if (sizes[r] < params.min_region_pixels || !planar[r]) continue;
    require(out.region_count < 65535, "segment_regions: more than 65535 regions");
    relabel[r] = static_cast<Label>(++out.region_count);
  }
  for (std::size_t i = 0; i < region_of.size(); ++i) {
    if (region_of[i] >= 0) out.labels.pixels()[i] = relabel[static_cast<std::size_t>(region_of[i])];
  }
  fill_from_planes(points, normals, params, out);
  return out;
}

namespace {

int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

int merge_coplanar_regions(const PointImage& points, RegionSegmentation& regions,
                           const CoplanarMergeParams& params) {
  const int w = points.width(), h = points.height();
  require(regions.labels.width() == w && regions.labels.height() == h,
          "merge_coplanar_regions: points and labels must have one size");
  require(params.max_angle_deg > 0 && params.max_angle_deg < 90 && params.max_offset > 0 &&
              params.max_gap_pixels >= 0,
          "merge_coplanar_regions: angle must be in (0, 90) degrees, offset > 0, gap >= 0");
  const auto n = static_cast<std::size_t>(regions.region_count);
  const LabelImage& labels = regions.labels;
  // Moments about the first point seen keep the sums well-conditioned.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  bool have_origin = false;
  std::vector<PlaneMoments> moments(n);
  std::set<std::pair<Label, Label>> pairs;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Label a = labels(x, y);
      if (a == kUnlabeled) continue;
      const Eigen::Vector3d p = vec3(points(x, y));
      if (!have_origin) origin = p, have_origin = true;
      moments[a - 1u].add(p - origin);
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        for (int step = 1; step <= 1 + params.max_gap_pixels; ++step) {
          const int u = x + step * dx, v = y + step * dy;
          if (u >= w || v >= h) break;
          const Label b = labels(u, v);
          if (b == kUnlabeled) continue;
          if (b != a) pairs.emplace(std::min(a, b), std::max(a, b));
          break;
        }
      }
    }
  }
  const double angle_cos = cos_deg(params.max_angle_deg);
  std::vector<int> parent(n);
  for (std::size_t k = 0; k < n; ++k) parent[k] = static_cast<int>(k);
  int merges = 0;
  for (const auto& [a, b] : pairs) {
    const int ra = find_root(parent, a - 1), rb = find_root(parent, b - 1);
    if (ra == rb) continue;
    const PlaneMoments& ma = moments[static_cast<std::size_t>(ra)];
    const PlaneMoments& mb = moments[static_cast<std::size_t>(rb)];
    const Eigen::Vector3d na = ma.normal(), nb = mb.normal();
    const Eigen::Vector3d ca = ma.centroid(), cb = mb.centroid();
    if (std::fabs(na.dot(nb)) < angle_cos || std::fabs(na.dot(cb - ca)) > params.max_offset ||
        std::fabs(nb.dot(ca - cb)) > params.max_offset) {
      continue;
    }
    const int keep = std::min(ra, rb), gone = std::max(ra, rb);
    moments[static_cast<std::size_t>(keep)].add(moments[static_cast<std::size_t>(gone)]);
    parent[static_cast<std::size_t>(gone)] = keep;
    ++merges;
  }
  if (merges == 0) return 0;
  std::vector<Label> relabel(n, kUnlabeled);
  Label next = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto root = static_cast<std::size_t>(find_root(parent, static_cast<int>(k)));
    if (relabel[root] == kUnlabeled) relabel[root] = ++next;
    relabel[k] = relabel[root];
  }
  for (Label& l : regions.labels.pixels()) {
    if (l != kUnlabeled) l = relabel[l - 1u];
  }
  regions.region_count = next;
  return merges;
}

std::vector<Label> split_offset_layers(const PointImage& smoothed_points,
                                       const NormalImage& normals, RegionSegmentation& regions,
                                       const LayerSplitParams& params) {
  const int w = smoothed_points.width(), h = smoothed_points.height();
  require(normals.width() == w && normals.height() == h && regions.labels.width() == w &&
              regions.labels.height() == h,
          "split_offset_layers: points, normals and labels must have one size");
  require(params.min_offset > 0 && params.min_pixels >= 1,
          "split_offset_layers: min_offset must be > 0 and min_pixels >= 1");
  const auto n = static_cast<std::size_t>(regions.region_count);
  std::vector<Eigen::Vector3d> normal(n, Eigen::Vector3d::Zero());
  std::vector<std::vector<double>> offsets(n);
  LabelImage& labels = regions.labels;
  for (int i = 0; i < w * h; ++i) {
    const Label l = labels.pixels()[static_cast<std::size_t>(i)];
    const Point4f& m = normals.pixels()[static_cast<std::size_t>(i)];
    if (l != kUnlabeled && is_valid(m)) normal[l - 1u] += vec3(m);
  }
  for (auto& v : normal) v.normalize();
  for (int i = 0; i < w * h; ++i) {
    const Label l = labels.pixels()[static_cast<std::size_t>(i)];
    if (l != kUnlabeled) {
      offsets[l - 1u].push_back(
          normal[l - 1u].dot(vec3(smoothed_points.pixels()[static_cast<std::size_t>(i)])));
    }
  }
  std::vector<double> plane(n, 0.0);
  for (std::size_t r = 0; r < n; ++r) {
    if (!offsets[r].empty()) plane[r] = quantile(offsets[r], 0.5);
  }
  // Side of each pixel: +1 in front of its region's plane, -1 behind, 0 on it.
  std::vector<int> side(static_cast<std::size_t>(w * h), 0);
  for (int i = 0; i < w * h; ++i) {
    const Label l = labels.pixels()[static_cast<std::size_t>(i)];
    if (l == kUnlabeled) continue;
    const double s =
        normal[l - 1u].dot(vec3(smoothed_points.pixels()[static_cast<std::size_t>(i)])) -
        plane[l - 1u];
    // Normals face the sensor, n . p = -distance to the plane: "in front" is positive.
    side[static_cast<std::size_t>(i)] = s > params.min_offset ? 1 : s < -params.min_offset ? -1 : 0;
  }
  std::vector<bool> visited(side.size(), false);
  std::vector<int> component;
  std::vector<Label> parents;
  for (int seed = 0; seed < w * h; ++seed) {
    const auto s = static_cast<std::size_t>(seed);
    if (side[s] == 0 || visited[s]) continue;
    const Label l = labels.pixels()[s];
    component.assign(1, seed);
    visited[s] = true;
    for (std::size_t head = 0; head < component.size(); ++head) {
      const int i = component[head], x = i % w, y = i / w;
      const int candidates[4] = {x > 0 ? i - 1 : -1, x + 1 < w ? i + 1 : -1, y > 0 ? i - w : -1,
                                 y + 1 < h ? i + w : -1};
      for (const int j : candidates) {
        const auto u = static_cast<std::size_t>(j);
        if (j < 0 || visited[u] || side[u] != side[s] || labels.pixels()[u] != l) continue;
        visited[u] = true;
        component.push_back(j);
      }
    }
    if (static_cast<int>(component.size()) < params.min_pixels) continue;
    require(regions.region_count < 65535, "split_offset_layers: more than 65535 regions");
    const auto label = static_cast<Label>(++regions.region_count);
    for (const int i : component) labels.pixels()[static_cast<std::size_t>(i)] = label;
    parents.push_back(l);
  }
  return parents;
}

namespace {

void check_measurable(const PointImage& points, const NormalImage& normals,
                      const RegionSegmentation& regions, const Eigen::Vector3d& up,
                      const MeasureParams& params) {
  const int w = points.width(), h = points.height();
  require(normals.width() == w && normals.height() == h && regions.labels.width() == w &&
              regions.labels.height() == h,
          "measure_regions: points, normals and labels must have one size");
  require(std::fabs(up.norm() - 1.0) < 1e-6, "measure_regions: up must be a unit vector");
  require(params.trim_fraction >= 0 && params.trim_fraction < 0.5,
          "measure_regions: trim_fraction must be in [0, 0.5)");
  require(params.occluder_relative_range >= 0 && params.occluder_relative_range < 1,
          "measure_regions: occluder_relative_range must be in [0, 1)");
  require(params.max_gap_fraction >= 0 && params.max_gap_fraction <= 1,
          "measure_regions: max_gap_fraction must be in [0, 1]");
}

// What measuring one region reads: the images and the parameters.
struct RegionInputs {
  const PointImage& points;
  const LabelImage& labels;
  const Eigen::Vector3d& up;
  const MeasureParams& params;
  int w, h;
};

// Each region's pixels (indices y * w + x) and the regions within adjacency_radius of it.
struct RegionPixels {
  std::vector<std::vector<int>> members;
  std::vector<std::set<Label>> adjacent;
};

// One raster pass: the pixels and neighbours of each region, and the sums of its points and
// normals into out's centroid and mean_normal.
RegionPixels gather_regions(const RegionInputs& in, const NormalImage& normals,
                            std::vector<RegionMeasurements>& out) {
  const int w = in.w, h = in.h;
  const LabelImage& labels = in.labels;
  RegionPixels pixels{std::vector<std::vector<int>>(out.size()),
                      std::vector<std::set<Label>>(out.size())};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Label l = labels(x, y);
      if (l == kUnlabeled) continue;
      RegionMeasurements& m = out[l - 1u];
      pixels.members[l - 1u].push_back(y * w + x);
      m.centroid += vec3(in.points(x, y));
      if (is_valid(normals(x, y))) m.mean_normal += vec3(normals(x, y));  // filled pixels have none
      for (int d = 1; d <= in.params.adjacency_radius; ++d) {
        for (const auto& [qx, qy] : {std::pair{x + d, y}, std::pair{x, y + d}}) {
          if (qx >= w || qy >= h) continue;
          const Label o = labels(qx, qy);
          if (o != kUnlabeled && o != l) {
            pixels.adjacent[l - 1u].insert(o);
            pixels.adjacent[o - 1u].insert(l);
          }
        }
      }
    }
  }
  return pixels;
}

// Area: the parallelogram towards each pixel's right and lower neighbours of the region,
// projected on the mean normal (depth noise would inflate the raw parallelogram).
void measure_area(const RegionInputs& in, const std::vector<int>& members, RegionMeasurements& m) {
  const PointImage& points = in.points;
  for (const int i : members) {
    const int x = i % in.w, y = i / in.w;
    if (x + 1 < in.w && y + 1 < in.h && in.labels(x + 1, y) == m.id &&
        in.labels(x, y + 1) == m.id) {
      m.area += std::fabs((vec3(points(x + 1, y)) - vec3(points(x, y)))
                              .cross(vec3(points(x, y + 1)) - vec3(points(x, y)))
                              .dot(m.mean_normal));
    }
  }
}

// The normal of the plane fitted to the region's points, turned like its mean normal.
Eigen::Vector3d fitted_plane_normal(const PointImage& points, const std::vector<int>& members,
                                    const RegionMeasurements& m) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int i : members) {
    const Eigen::Vector3d d = vec3(points.pixels()[static_cast<std::size_t>(i)]) - m.centroid;
    scatter += d * d.transpose();
  }
  Eigen::Vector3d normal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  if (normal.dot(m.mean_normal) < 0) normal = -normal;
  return normal;
}

// Horizontal axis: in the plane and horizontal for a vertical region; for others the major
// principal axis of the points projected onto the horizontal plane.
Eigen::Vector3d horizontal_axis(const RegionInputs& in, const std::vector<int>& members,
                                const RegionMeasurements& m) {
  const Eigen::Vector3d& up = in.up;
  if (m.orientation == RegionOrientation::vertical) return up.cross(m.mean_normal).normalized();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int i : members) {
    Eigen::Vector3d d = vec3(in.points.pixels()[static_cast<std::size_t>(i)]) - m.centroid;
    d -= d.dot(up) * up;
    scatter += d * d.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
}

// The trimmed height range and the trimmed width along the horizontal axis.
void measure_extent(const RegionInputs& in, const std::vector<int>& members,
                    RegionMeasurements& m) {
  const Eigen::Vector3d axis = horizontal_axis(in, members, m);
  std::vector<double> heights, along;
  heights.reserve(members.size());
  along.reserve(members.size());
  for (const int i : members) {
    const Eigen::Vector3d p = vec3(in.points.pixels()[static_cast<std::size_t>(i)]);
    heights.push_back(p.dot(in.up));
    along.push_back(p.dot(axis));
  }
  trimmed_extent(heights, in.params.trim_fraction, m.min_height, m.max_height);
  double low = 0, high = 0;
  m.width = trimmed_extent(along, in.params.trim_fraction, low, high);
}

// What lies past a region's pixel (x, y) in direction (dx, dy), over any pixels without a point:
// nothing seen (the border, a wide gap, a plane seen edge-on: the surface may go on), a nearer
// surface of another region (hiding it), or the surface itself or what lies behind it (no cut).
enum class Beyond { open, nearer, seen };

// Past a gap, the first point compared with the region's plane extended along its ray: a point
// in front of the plane hides where the surface goes; one on or behind it shows the surface in
// view past the gap (a dropout) or ending within it (the grazing top behind a table's edge).
Beyond compare_with_plane(const RegionMeasurements& m, const Eigen::Vector3d& q, double margin) {
  const Eigen::Vector3d ray = q.normalized();
  const double towards = m.plane_normal.dot(ray);
  if (std::fabs(towards) < 0.1) return Beyond::open;  // the plane seen edge-on: no verdict
  const double on_plane = m.plane_normal.dot(m.centroid) / towards;
  if (on_plane <= 0) return Beyond::open;
  return q.norm() < on_plane - margin ? Beyond::nearer : Beyond::seen;
}

// `occluder`: the nearer point, where the answer is Beyond::nearer.
Beyond look_beyond(const RegionInputs& in, const RegionMeasurements& m, int x, int y, int dx,
                   int dy, double range, Eigen::Vector3d& occluder) {
  const PointImage& points = in.points;
  const int max_gap = static_cast<int>(in.params.max_gap_fraction * std::max(in.w, in.h));
  for (int step = 1; step <= max_gap + 1; ++step) {
    const int qx = x + step * dx, qy = y + step * dy;
    if (qx < 0 || qy < 0 || qx >= in.w || qy >= in.h) return Beyond::open;
    const Point4f& q = points(qx, qy);
    if (!is_valid(q)) continue;
    const double margin = in.params.occluder_relative_range * range;
    occluder = vec3(q);
    if (step > 1) return compare_with_plane(m, occluder, margin);
    if (in.labels(qx, qy) != m.id && q.head<3>().norm() < range - margin) return Beyond::nearer;
    return Beyond::seen;
  }
  return Beyond::open;  // a wider gap: unmeasured surface (glass, black, out of range)
}

// Which way a vertical region's surface runs towards an opening at (x + dx, y + dy): from the
// region's own pixel on the other side, so that a short region (a table's edge band) cut at its
// end is cut sideways, not above and below. Other regions, or no such pixel: by height alone.
enum class Opening { up, down, sideways, by_height };

Opening opening_direction(const RegionInputs& in, const RegionMeasurements& m, int x, int y, int dx,
                          int dy) {
  const int bx = x - dx, by = y - dy;
  if (m.orientation != RegionOrientation::vertical || (dx == 0 && dy == 0) || bx < 0 || by < 0 ||
      bx >= in.w || by >= in.h || in.labels(bx, by) != m.id)
    return Opening::by_height;
  const Eigen::Vector3d run = vec3(in.points(x, y)) - vec3(in.points(bx, by));
  const double length = run.norm();
  if (length <= 0) return Opening::by_height;
  const double rise = run.dot(in.up) / length;
  return rise > 0.5 ? Opening::up : rise < -0.5 ? Opening::down : Opening::sideways;
}

// Where the region meets the image border or a pixel without a point, the surface may go on
// out of view: classify that spot by its height within the region. Missing depth with a surface
// on or behind the region's plane beyond it is no cut: a dropout inside the surface, or its own
// edge (depth is lost along occluding edges and on grazing surfaces such as a table top).
void find_cuts(const RegionInputs& in, const std::vector<int>& members, RegionMeasurements& m) {
  const int w = in.w;
  const PointImage& points = in.points;
  const double band = std::max(0.1, 0.15 * m.height());
  std::vector<double> offsets_above;
  for (const int i : members) {
    const int x = i % w, y = i / w;
    const double range = vec3(points(x, y)).norm();
    bool open = false, occluded = false;
    int open_dx = 0, open_dy = 0;
    Eigen::Vector3d occluder = Eigen::Vector3d::Zero(), hiding_point = occluder;
    for (const auto& [dx, dy] :
         {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
      const Beyond beyond = look_beyond(in, m, x, y, dx, dy, range, occluder);
      if (beyond == Beyond::open) {
        open = true;
        open_dx = dx, open_dy = dy;
      } else if (beyond == Beyond::nearer) {
        occluded = true;  // a nearer surface of another region hides what lies behind it
        if (!open) open_dx = dx, open_dy = dy, hiding_point = occluder;
      }
    }
    if (!open && !occluded) continue;
    const double height = vec3(points(x, y)).dot(in.up);
    const Opening way = opening_direction(in, m, x, y, open_dx, open_dy);
    const bool top =
        height >= m.max_height - band && way != Opening::down && way != Opening::sideways;
    const bool bottom =
        height <= m.min_height + band && way != Opening::up && way != Opening::sideways;
    if (open) {
      m.cut_above = m.cut_above || top;
      m.cut_below = m.cut_below || bottom;
      m.cut_sideways = m.cut_sideways || (!top && !bottom);
    } else {
      if (top) offsets_above.push_back(m.plane_normal.dot(hiding_point - m.centroid));
      m.occluded_above = m.occluded_above || top;
      m.occluded_below = m.occluded_below || bottom;
      m.occluded_sideways = m.occluded_sideways || (!top && !bottom);
    }
  }
  if (!offsets_above.empty()) m.occluder_offset_above = quantile(offsets_above, 0.5);
}

}  // namespace

std::vector<RegionMeasurements> measure_regions(const PointImage& points,
                                                const NormalImage& normals,
                                                const RegionSegmentation& regions,
                                                const Eigen::Vector3d& up,
                                                const MeasureParams& params) {
  check_measurable(points, normals, regions, up, params);
  const RegionInputs in{points, regions.labels, up, params, points.width(), points.height()};
  const auto n_regions = static_cast<std::size_t>(regions.region_count);
  std::vector<RegionMeasurements> out(n_regions);
  const RegionPixels pixels = gather_regions(in, normals, out);
  const double horizontal_cos = cos_deg(params.horizontal_tolerance_deg);
  const double vertical_sin = std::sin(params.vertical_tolerance_deg * std::numbers::pi / 180.0);
  for (std::size_t r = 0; r < n_regions; ++r) {
    RegionMeasurements& m = out[r];
    const std::vector<int>& members = pixels.members[r];
    m.id = static_cast<Label>(r + 1);
    require(!members.empty(), "measure_regions: region " + std::to_string(r + 1) + " of " +
                                  std::to_string(n_regions) + " has no pixel");
    m.pixel_count = static_cast<int>(members.size());
    m.centroid /= m.pixel_count;
    m.mean_normal.normalize();
    measure_area(in, members, m);
    m.neighbours.assign(pixels.adjacent[r].begin(), pixels.adjacent[r].end());
    const double along_up = m.mean_normal.dot(up);
    m.orientation = std::fabs(along_up) >= horizontal_cos ? RegionOrientation::horizontal
                    : std::fabs(along_up) <= vertical_sin ? RegionOrientation::vertical
                                                          : RegionOrientation::other;
    m.plane_normal = fitted_plane_normal(points, members, m);
    measure_extent(in, members, m);
    find_cuts(in, members, m);
  }
  return out;
}

}  // namespace kartograf::semantic
