#include "kartograf/synth/ray_caster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "kartograf/core/error.hpp"

namespace kartograf::synth {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinT = 1e-9;

// A ray prepared for slab tests: inverse direction (a huge finite value where a component is 0, so
// that no 0 * inf NaN can arise) and, per axis, which side of a box it meets first.
struct SlabRay {
  Eigen::Vector3d o;
  double inv[3];
  int first[3];  // 0: the min side (direction >= 0), 1: the max side

  SlabRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& d) : o(origin) {
    for (int a = 0; a < 3; ++a) {
      inv[a] = d[a] != 0.0 ? 1.0 / d[a] : (std::signbit(d[a]) ? -1e300 : 1e300);
      first[a] = inv[a] < 0 ? 1 : 0;
    }
  }
  // Entry and exit parameters of the slab of axis a.
  double enter(const double (&b)[2][3], int a) const { return (b[first[a]][a] - o[a]) * inv[a]; }
  double leave(const double (&b)[2][3], int a) const {
    return (b[1 - first[a]][a] - o[a]) * inv[a];
  }
};

// Slab test: the ray parameter where it enters the box and the axis of the entry face; false
// when it misses, or the box is behind or around the origin.
inline bool enter_box(const double (&b)[2][3], const SlabRay& r, double& t_enter, int& axis) {
  const double tx = r.enter(b, 0), ty = r.enter(b, 1), tz = r.enter(b, 2);
  double near = tx;
  int near_axis = 0;
  if (ty > near) near = ty, near_axis = 1;
  if (tz > near) near = tz, near_axis = 2;
  const double far = std::min(r.leave(b, 0), std::min(r.leave(b, 1), r.leave(b, 2)));
  if (near > far || near <= kMinT) return false;
  t_enter = near;
  axis = near_axis;
  return true;
}

// Whether the ray passes through the box somewhere in (0, before).
inline bool crosses_box(const double (&b)[2][3], const SlabRay& r, double before) {
  const double near = std::max(r.enter(b, 0), std::max(r.enter(b, 1), r.enter(b, 2)));
  const double far = std::min(r.leave(b, 0), std::min(r.leave(b, 1), r.leave(b, 2)));
  return near <= far && far > kMinT && near < before;
}

// A ray's inverse direction for the grid walk: 0 where a component is 0 (flagged in zero).
struct GridRay {
  bool zero[3];
  Eigen::Vector3d inv;

  explicit GridRay(const Eigen::Vector3d& d) {
    for (int a = 0; a < 3; ++a) {
      zero[a] = d[a] == 0.0;
      inv[a] = zero[a] ? 0.0 : 1.0 / d[a];
    }
  }
};

// The nearest surface found so far along a ray.
struct NearestHit {
  double t = kInf;
  int solid = -3;  // -1 floor, -2 ceiling, -3 nothing
  int axis = 2;    // of the face hit
};

// Floor and ceiling bound every ray that is not horizontal.
NearestHit floor_or_ceiling(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const GridRay& r,
                            double height) {
  NearestHit hit;
  if (d.z() < 0 && o.z() > 0) {
    hit.t = -o.z() * r.inv.z();
    hit.solid = -1;
  } else if (d.z() > 0 && o.z() < height) {
    hit.t = (height - o.z()) * r.inv.z();
    hit.solid = -2;
  }
  return hit;
}

// The uniform grid over the floor plan: nx by ny cells of size cell from min.
struct GridFrame {
  Eigen::Vector2d min;
  double cell;
  int nx, ny;
};

// The part of the ray over the grid: [t_lo, t_hi], empty when t_lo > t_hi.
std::pair<double, double> span_over_grid(const GridFrame& g, const Eigen::Vector3d& o,
                                         const GridRay& r) {
  double t_lo = 0, t_hi = kInf;
  const Eigen::Vector2d grid_max = g.min + g.cell * Eigen::Vector2d(g.nx, g.ny);
  for (int a = 0; a < 2; ++a) {
    if (r.zero[a]) {
      if (o[a] < g.min[a] || o[a] > grid_max[a]) t_hi = -1;
      continue;
    }
    double t0 = (g.min[a] - o[a]) * r.inv[a], t1 = (grid_max[a] - o[a]) * r.inv[a];
    if (t0 > t1) std::swap(t0, t1);
    t_lo = std::max(t_lo, t0);
    t_hi = std::min(t_hi, t1);
  }
  return {t_lo, t_hi};
}

// Walks the grid cells along the ray from t_lo (a DDA walk): test_cell(c) tests the boxes of cell
// c and returns the ray parameter of the nearest hit so far. The walk stops at the first cell
// whose hit lies before the ray leaves it, or where the ray leaves the grid.
template <class TestCell>
void walk_cells(const GridFrame& g, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                const GridRay& r, double t_lo, double t_hi, TestCell&& test_cell) {
  const Eigen::Vector2d start = o.head<2>() + t_lo * d.head<2>();
  int cx = std::clamp(static_cast<int>(std::floor((start.x() - g.min.x()) / g.cell)), 0, g.nx - 1);
  int cy = std::clamp(static_cast<int>(std::floor((start.y() - g.min.y()) / g.cell)), 0, g.ny - 1);
  const int step_x = d.x() > 0 ? 1 : -1, step_y = d.y() > 0 ? 1 : -1;
  // Ray parameters of the next cell borders, and between borders.
  auto next_border = [&](int a, int c, int step) {
    if (r.zero[a]) return kInf;
    const double border = g.min[a] + g.cell * (c + (step > 0 ? 1 : 0));
    return (border - o[a]) * r.inv[a];
  };
  double t_next_x = next_border(0, cx, step_x), t_next_y = next_border(1, cy, step_y);
  const double dt_x = r.zero[0] ? kInf : g.cell * std::fabs(r.inv.x());
  const double dt_y = r.zero[1] ? kInf : g.cell * std::fabs(r.inv.y());
  for (;;) {
    const double best = test_cell(static_cast<std::size_t>(cy) * g.nx + cx);
    const double t_exit = std::min({t_next_x, t_next_y, t_hi});
    if (best <= t_exit || t_exit >= t_hi) break;
    if (t_next_x < t_next_y) {
      cx += step_x;
      t_next_x += dt_x;
      if (cx < 0 || cx >= g.nx) break;
    } else {
      cy += step_y;
      t_next_y += dt_y;
      if (cy < 0 || cy >= g.ny) break;
    }
  }
}

}  // namespace

RayCaster::RayCaster(const World& world, double cell_size) : world_(world), cell_(cell_size) {
  require(cell_size > 0, "RayCaster: cell size must be positive");
  const Rect2 bounds = world.bounds.expanded(0.01);
  grid_min_ = bounds.min;
  nx_ = std::max(1, static_cast<int>(std::ceil(bounds.size().x() / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(bounds.size().y() / cell_)));
  const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);

  // Groups: each piece of furniture, then every other solid on its own.
  std::vector<Group> groups;
  std::vector<bool> grouped(world.solids.size(), false);
  auto add_group = [&](const std::vector<int>& solids) {
    Group g{{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}},
            static_cast<std::uint32_t>(parts_.size()),
            static_cast<std::uint32_t>(solids.size())};
    for (int i : solids) {
      const Box3& box = world.solids[static_cast<std::size_t>(i)].box;
      Part part{{}, i};
      for (int a = 0; a < 3; ++a) {
        part.bounds[0][a] = box.min[a];
        part.bounds[1][a] = box.max[a];
        g.bounds[0][a] = std::min(g.bounds[0][a], box.min[a]);
        g.bounds[1][a] = std::max(g.bounds[1][a], box.max[a]);
      }
      parts_.push_back(part);
      grouped[static_cast<std::size_t>(i)] = true;
    }
    groups.push_back(g);
  };
  for (const Furniture& item : world.furniture) add_group(item.solids);
  for (std::size_t i = 0; i < world.solids.size(); ++i) {
    if (!grouped[i]) add_group({static_cast<int>(i)});
  }

  // Cells overlapped by each group's footprint (closed: a box on a cell border goes in both).
  auto cell_range = [&](const Group& g, int& x0, int& x1, int& y0, int& y1) {
    auto cell = [&](double v, int axis, int count) {
      return std::clamp(static_cast<int>(std::floor((v - grid_min_[axis]) / cell_)), 0, count - 1);
    };
    x0 = cell(g.bounds[0][0], 0, nx_);
    x1 = cell(g.bounds[1][0], 0, nx_);
    y0 = cell(g.bounds[0][1], 1, ny_);
    y1 = cell(g.bounds[1][1], 1, ny_);
  };
  std::vector<std::uint32_t> counts(cells, 0);
  for (const Group& g : groups) {
    int x0, x1, y0, y1;
    cell_range(g, x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) ++counts[static_cast<std::size_t>(y) * nx_ + x];
    }
  }
  cell_start_.assign(cells + 1, 0);
  for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] = cell_start_[c] + counts[c];
  groups_.resize(cell_start_[cells]);
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (const Group& g : groups) {
    int x0, x1, y0, y1;
    cell_range(g, x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) groups_[fill[static_cast<std::size_t>(y) * nx_ + x]++] = g;
    }
  }
}

Eigen::Vector3d surface_albedo(const World& world, const SurfaceHit& hit) {
  const Eigen::Vector3d& p = hit.point;
  const int axis = face_axis(hit.face);
  const double u = axis == 0 ? p.y() : p.x();
  const double v = axis == 2 ? p.y() : p.z();
  return world.materials[static_cast<std::size_t>(hit.material)].albedo(u, v);
}

void RayCaster::resolve(SurfaceHit& hit, int solid) const {
  if (solid == -1) {  // floor
    hit.plane = world_.floor_plane;
    hit.material = world_.floor_material_at(hit.point.head<2>());
    return;
  }
  if (solid == -2) {  // ceiling
    hit.plane = world_.ceiling_plane;
    hit.material = world_.ceiling_material;
    return;
  }
  const Solid& s = world_.solids[static_cast<std::size_t>(solid)];
  if (s.kind == SolidKind::object) {
    hit.plane = s.face_planes[static_cast<int>(hit.face)];
    hit.material = s.material;
    return;
  }
  hit.plane = world_.wall_plane_at(hit.point, hit.face);
  hit.material = hit.plane ? world_.plane(hit.plane).material : world_.rooms.front().wall_material;
}

std::optional<SurfaceHit> RayCaster::cast(const Eigen::Vector3d& o,
                                          const Eigen::Vector3d& d) const {
  const SlabRay ray(o, d);
  const GridRay grid_ray(d);
  NearestHit best = floor_or_ceiling(o, d, grid_ray, world_.height);
  const GridFrame grid{grid_min_, cell_, nx_, ny_};
  const auto [t_lo, t_hi] = span_over_grid(grid, o, grid_ray);
  const auto test_cell = [&](std::size_t c) {
    for (std::uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) {
      const Group& g = groups_[i];
      if (g.count > 1 && !crosses_box(g.bounds, ray, best.t)) continue;
      for (std::uint32_t k = g.first; k < g.first + g.count; ++k) {
        const Part& part = parts_[k];
        double t;
        int axis;
        if (enter_box(part.bounds, ray, t, axis) && t < best.t) best = {t, part.solid, axis};
      }
    }
    return best.t;
  };
  if (t_lo <= t_hi && t_lo < best.t) walk_cells(grid, o, d, grid_ray, t_lo, t_hi, test_cell);

  if (best.solid == -3) return std::nullopt;
  SurfaceHit hit;
  hit.t = best.t;
  hit.point = o + best.t * d;
  if (best.solid >= 0) {
    hit.face = make_face(best.axis, d[best.axis] < 0);
    // Snap the hit onto the face exactly (the product above rounds).
    const Box3& box = world_.solids[static_cast<std::size_t>(best.solid)].box;
    hit.point[best.axis] = d[best.axis] < 0 ? box.max[best.axis] : box.min[best.axis];
  } else {
    hit.face = best.solid == -1 ? Face::pos_z : Face::neg_z;
    hit.point.z() = best.solid == -1 ? 0.0 : world_.height;
  }
  resolve(hit, best.solid);
  return hit;
}

}  // namespace kartograf::synth
