#include "kartograf/semantic/classify.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include <Eigen/Geometry>

#include "kartograf/core/error.hpp"
#include "kartograf/core/memory_budget.hpp"

namespace kartograf::semantic {
namespace {

double cos_deg(double degrees) {
  return std::cos(degrees * std::numbers::pi / 180.0);
}

// The floor and ceiling levels the rules compare with, filled in from the assumed room height
// when only one of them is in view.
struct Levels {
  std::optional<double> floor, ceiling;
};

Levels room_levels(const GravityEstimate& gravity, const ClassificationParams& params) {
  Levels levels{gravity.floor_height, gravity.ceiling_height};
  if (levels.floor && levels.ceiling && *levels.ceiling - *levels.floor < params.door_min_height) {
    levels.ceiling.reset();  // a low "ceiling" (a table's underside seen from below) is no room
  }
  // The sensor (height 0) stands between floor and ceiling, whatever the assumed room height.
  if (levels.floor && !levels.ceiling) {
    levels.ceiling = std::max(*levels.floor + params.assumed_room_height, 0.0);
  }
  if (levels.ceiling && !levels.floor) {
    levels.floor = std::min(*levels.ceiling - params.assumed_room_height, 0.0);
  }
  return levels;
}

class RegionRules {
 public:
  RegionRules(std::span<const RegionMeasurements> regions, const GravityEstimate& gravity,
              const ClassificationParams& params)
      : regions_(regions),
        up_(gravity.up),
        params_(params),
        levels_(room_levels(gravity, params)) {}

  bool reaches_floor(const RegionMeasurements& r) const {
    return levels_.floor && r.min_height <= *levels_.floor + params_.reach_tolerance;
  }
  bool reaches_ceiling(const RegionMeasurements& r) const {
    return levels_.ceiling && r.max_height >= *levels_.ceiling - params_.reach_tolerance;
  }
  double height_above_floor(double height) const {
    return levels_.floor ? height - *levels_.floor : height;
  }

  bool is_floor(const RegionMeasurements& r) const {
    return r.orientation == RegionOrientation::horizontal && r.mean_normal.dot(up_) > 0 &&
           levels_.floor &&
           std::fabs(r.centroid.dot(up_) - *levels_.floor) <= params_.floor_tolerance;
  }
  // At the ceiling's height, or (a lowered part of a high ceiling) above any door's lintel.
  bool is_ceiling(const RegionMeasurements& r, const GravityEstimate& gravity) const {
    if (r.orientation != RegionOrientation::horizontal || r.mean_normal.dot(up_) >= 0 ||
        !gravity.ceiling_height) {
      return false;
    }
    const double height = r.centroid.dot(up_);
    return std::fabs(height - *gravity.ceiling_height) <= params_.ceiling_tolerance ||
           height_above_floor(height) >= params_.door_max_height + params_.reach_tolerance;
  }

  // The paper's height test, or the view explains why the visible part falls short.
  bool wall_height(const RegionMeasurements& r) const {
    if (levels_.floor && levels_.ceiling &&
        r.height() >= params_.wall_height_fraction * (*levels_.ceiling - *levels_.floor)) {
      return true;
    }
    return (reaches_floor(r) || r.cut_below) && (reaches_ceiling(r) || r.cut_above);
  }
  // Seen from the ceiling down to where a nearer surface hides it (furniture in front of a wall,
  // or a scanner whose view starts at its own height).
  bool ceiling_high(const RegionMeasurements& r) const {
    return reaches_ceiling(r) && (reaches_floor(r) || r.cut_below || r.occluded_below);
  }

  // Door-sized where seen; an end out of view (cut by the image or an occluder) is not held
  // against it, as long as half a door's height is in view.
  bool door_shaped(const RegionMeasurements& r) const {
    if (r.orientation != RegionOrientation::vertical) return false;
    if (r.width > params_.door_max_width) return false;
    if (r.width < params_.door_min_width && !r.cut_sideways) return false;  // a close-up of a leaf
    if (!reaches_floor(r) && !r.cut_below) return false;
    const double top = height_above_floor(r.max_height);
    if (top > params_.door_max_height) return false;
    if (r.height() < 0.5 * params_.door_min_height) return false;
    return top >= params_.door_min_height || r.cut_above;
  }

  // A wall parallel to r, r standing door_min..max_wall_offset in front of it (a leaf open
  // against it) or, with its top in view and below the wall's, door_min_wall_offset..
  // door_max_recess behind it (a closed door in its frame), and next to r: a neighbour, a
  // neighbour's neighbour (the leaf's own edge face often lies between), or within
  // door_max_wall_gap of r along the wall (the wall behind a leaf is hidden by it, and the
  // visible pieces beside it may be parted from it by a jamb or by clutter).
  bool beside_parallel_wall(const RegionMeasurements& r,
                            const std::vector<SemanticClass>& classes) const {
    const double min_offset = std::max(params_.door_min_wall_offset,
                                       params_.door_relative_wall_offset * r.centroid.norm());
    auto parallel_wall = [&](Label id) {
      const RegionMeasurements& o = regions_[id - 1u];
      if (classes[id - 1u] != SemanticClass::wall || id == r.id) return false;
      if (o.mean_normal.dot(r.mean_normal) < cos_deg(params_.parallel_tolerance_deg)) return false;
      // Distance of r's centroid from the wall's plane, positive towards the sensor (normals face
      // it).
      const double in_front = o.plane_normal.dot(r.centroid - o.centroid);
      if (in_front >= min_offset) return in_front <= params_.door_max_wall_offset;
      return recessed_in(r, o, -in_front, min_offset);
    };
    for (const Label id : r.neighbours) {
      if (parallel_wall(id)) return true;
      const auto& second = regions_[id - 1u].neighbours;
      if (std::any_of(second.begin(), second.end(), parallel_wall)) return true;
    }
    for (const RegionMeasurements& o : regions_) {
      if (!parallel_wall(o.id)) continue;
      const Eigen::Vector3d along = up_.cross(o.plane_normal).normalized();
      const double gap = std::fabs(along.dot(r.centroid - o.centroid)) - 0.5 * (r.width + o.width);
      if (gap <= params_.door_max_wall_gap) return true;
    }
    return false;
  }

  // A closed door sits in its frame, behind the wall's face by up to the wall's thickness: its
  // top edge is in view and the wall, no door itself, goes on above it (a wall's step back
  // reaches the ceiling, and a wall seen through a doorway lies a room further back).
  bool recessed_in(const RegionMeasurements& r, const RegionMeasurements& wall, double behind,
                   double min_offset) const {
    return behind >= min_offset && behind <= params_.door_max_recess && !r.cut_above &&
           wall.max_height >= r.max_height + params_.door_min_lintel && !door_shaped(wall);
  }

  // In the plane of a wall (parallel, centroid within coplanar_wall_offset of the wall's plane)
  // and no farther than coplanar_wall_gap from it along the wall: the same wall, parted from its
  // labelled part by windows, pictures or clutter.
  bool in_wall_plane(const RegionMeasurements& r, const std::vector<SemanticClass>& classes) const {
    if (r.orientation != RegionOrientation::vertical) return false;
    return std::any_of(regions_.begin(), regions_.end(), [&](const RegionMeasurements& o) {
      return classes[o.id - 1u] == SemanticClass::wall && o.id != r.id &&
             coplanar_within(r, o, params_.coplanar_wall_gap);
    });
  }
  // r in o's plane (parallel, r's centroid within coplanar_wall_offset of it) and no farther than
  // `gap` from o along it.
  bool coplanar_within(const RegionMeasurements& r, const RegionMeasurements& o, double gap) const {
    if (o.plane_normal.dot(r.plane_normal) < cos_deg(params_.parallel_tolerance_deg)) return false;
    if (std::fabs(o.plane_normal.dot(r.centroid - o.centroid)) > params_.coplanar_wall_offset)
      return false;
    const Eigen::Vector3d along = up_.cross(o.plane_normal).normalized();
    return std::fabs(along.dot(r.centroid - o.centroid)) - 0.5 * (r.width + o.width) <= gap;
  }

  // Stands on the floor and ends below the ceiling, within furniture size.
  bool furniture_sized(const RegionMeasurements& r) const {
    if (!levels_.floor || reaches_ceiling(r) || r.width > params_.furniture_max_width) return false;
    const double top = height_above_floor(r.max_height);
    return top >= params_.furniture_min_height && top <= params_.furniture_max_height &&
           height_above_floor(r.min_height) >= -params_.reach_tolerance;
  }
  // A top or a shelf board (facing up), or an underside (facing down).
  bool furniture_face(const RegionMeasurements& r) const {
    if (!furniture_sized(r)) return false;
    if (r.orientation == RegionOrientation::horizontal) return true;
    // A side or a front: from the floor (seen there or hidden), and wholly in view above.
    return r.orientation == RegionOrientation::vertical && !r.cut_above && !goes_on_above(r) &&
           (reaches_floor(r) || r.cut_below || r.occluded_below);
  }
  // Hidden above by a nearer surface standing further before it than a shelf is deep, and its
  // plane seen again above that: the wall between a table's legs and above its top, whose end the
  // view does not show (a leg hidden by the top has no such piece; a shelf's back below a board
  // stays furniture; tall furniture behind a table, going on above it, is unknown as well).
  bool goes_on_above(const RegionMeasurements& r) const {
    if (!r.occluded_above || r.occluder_offset_above <= params_.shelf_max_depth) return false;
    return std::any_of(regions_.begin(), regions_.end(), [&](const RegionMeasurements& o) {
      return o.id != r.id && o.orientation == RegionOrientation::vertical &&
             o.max_height > r.max_height + params_.reach_tolerance &&
             coplanar_within(r, o, params_.coplanar_wall_gap);
    });
  }

  bool beside(const RegionMeasurements& r, const std::vector<SemanticClass>& classes,
              SemanticClass wanted) const {
    return std::any_of(r.neighbours.begin(), r.neighbours.end(),
                       [&](Label id) { return classes[id - 1u] == wanted; });
  }

 private:
  std::span<const RegionMeasurements> regions_;
  Eigen::Vector3d up_;
  const ClassificationParams& params_;
  Levels levels_;
};

// Least-squares residual (rms) of t ~ a * index + b, relative to the spread of t.
double relative_line_residual(const std::vector<double>& index, const std::vector<double>& t) {
  const auto n = static_cast<double>(t.size());
  double si = 0, st = 0, sii = 0, sit = 0, stt = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    si += index[k], st += t[k], sii += index[k] * index[k], sit += index[k] * t[k];
    stt += t[k] * t[k];
  }
  const double var_i = sii / n - (si / n) * (si / n), var_t = stt / n - (st / n) * (st / n);
  if (var_i <= 0 || var_t <= 0) return 1.0;
  const double cov = sit / n - (si / n) * (st / n);
  return std::sqrt(std::max(0.0, var_t - cov * cov / var_i) / var_t);
}

// Furniture faces among the regions left unknown, then the unknown regions of furniture size that
// join them (a table's edge band, a cabinet's handle side), until nothing changes.
void label_furniture(std::span<const RegionMeasurements> regions, const RegionRules& rules,
                     std::vector<SemanticClass>& classes) {
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (classes[i] == SemanticClass::unknown && rules.furniture_face(regions[i]))
      classes[i] = SemanticClass::furniture;
  }
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < regions.size(); ++i) {
      if (classes[i] != SemanticClass::unknown || !rules.furniture_sized(regions[i]) ||
          !rules.beside(regions[i], classes, SemanticClass::furniture))
        continue;
      classes[i] = SemanticClass::furniture;
      changed = true;
    }
  }
}

}  // namespace

bool is_camera_frame(const PointImage& points) {
  std::vector<double> columns, rows, u, v;
  for (int y = 0; y < points.height(); ++y) {
    for (int x = 0; x < points.width(); ++x) {
      const Point4f& p = points(x, y);
      if (!is_valid(p)) continue;
      if (p.z() <= 0) return false;  // a camera sees only in front of it
      columns.push_back(x), rows.push_back(y);
      u.push_back(p.x() / p.z()), v.push_back(p.y() / p.z());
    }
  }
  constexpr double kMaxResidual = 0.01;  // a scan's angles are far from linear in tan
  return columns.size() >= 3 && relative_line_residual(columns, u) <= kMaxResidual &&
         relative_line_residual(rows, v) <= kMaxResidual;
}

std::vector<SemanticClass> classify_regions(std::span<const RegionMeasurements> regions,
                                            const GravityEstimate& gravity,
                                            const ClassificationParams& params) {
  const RegionRules rules(regions, gravity, params);
  std::vector<SemanticClass> classes(regions.size(), SemanticClass::unknown);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (rules.is_floor(regions[i])) classes[i] = SemanticClass::floor;
    if (rules.is_ceiling(regions[i], gravity)) classes[i] = SemanticClass::ceiling;
  }
  // Walls: the full rule first, then tall regions joined to a wall (its width test passes through
  // the neighbour), until nothing changes.
  auto candidate = [&](std::size_t i) {
    return classes[i] == SemanticClass::unknown &&
           regions[i].orientation == RegionOrientation::vertical &&
           (rules.wall_height(regions[i]) || rules.ceiling_high(regions[i]));
  };
  auto wide = [&](const RegionMeasurements& r) {
    return r.width >= params.wall_min_width || r.cut_sideways ||
           (r.occluded_sideways && rules.ceiling_high(r));
  };
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (candidate(i) && wide(regions[i])) {
      classes[i] = SemanticClass::wall;
    }
  }
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t i = 0; i < regions.size(); ++i) {
      const bool joined = candidate(i) && rules.beside(regions[i], classes, SemanticClass::wall);
      const bool coplanar = classes[i] == SemanticClass::unknown &&
                            regions[i].area >= params.coplanar_wall_min_area &&
                            rules.in_wall_plane(regions[i], classes);
      if (joined || coplanar) {
        classes[i] = SemanticClass::wall;
        changed = true;
      }
    }
  }
  // Doors among the door-shaped regions, walls so far or not: a leaf in front of a wall, or a
  // closed door behind the face of a wall that is not door-shaped, so two regions never make
  // each other doors.
  const std::vector<SemanticClass> walls = classes;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if ((classes[i] == SemanticClass::unknown || classes[i] == SemanticClass::wall) &&
        rules.door_shaped(regions[i]) && rules.beside_parallel_wall(regions[i], walls)) {
      classes[i] = SemanticClass::door;
    }
  }
  // Door jambs and wall pieces reaching above door height next to a wall; lintel undersides.
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const RegionMeasurements& r = regions[i];
    if (classes[i] != SemanticClass::unknown || !rules.beside(r, classes, SemanticClass::wall))
      continue;
    const bool jamb = r.orientation == RegionOrientation::vertical &&
                      rules.height_above_floor(r.max_height) >= params.door_min_height - 0.1;
    const bool lintel =
        r.orientation == RegionOrientation::horizontal && r.mean_normal.dot(gravity.up) < 0;
    if (jamb || lintel) classes[i] = SemanticClass::wall;
  }
  label_furniture(regions, rules, classes);
  return classes;
}

SemanticLabelling label_organized_points(const compute::Context& context, const PointImage& points,
                                         const LabellingParams& params) {
  // Smoothed copies, normals, regions and their working images: `kartograf semantic` on one
  // synthetic frame took 99 bytes more per pixel at 1280x960 than at 320x240; half again.
  constexpr double kBytesPerPixel = 150;
  require_fits_in_memory(kBytesPerPixel * static_cast<double>(points.size()),
                         "semantic labelling of a " + std::to_string(points.width()) + " x " +
                             std::to_string(points.height()) + " point image");
  SemanticLabelling out;
  // Measured once, for both smoothing windows.
  const RangeNoiseProfile noise =
      params.normals.noise_sigmas > 0 ? estimate_range_noise(points) : RangeNoiseProfile{};
  const PointImage smoothed = smooth_organized_points(points, params.normals, noise);
  NormalsImageParams presmoothed = params.normals;
  presmoothed.smoothing_radius = 0;
  out.normals = estimate_organized_normals(context, smoothed, presmoothed);
  out.regions = segment_regions(points, out.normals, params.regions);
  merge_coplanar_regions(points, out.regions, params.merge);
  const int unsplit_count = out.regions.region_count;
  // Offsets from a narrower window than the normals': a wide one blurs a leaf's 5 cm step into
  // the wall around it, and the blurred band stays with the leaf.
  NormalsImageParams layer_smoothing = params.normals;
  layer_smoothing.smoothing_radius = params.layers.smoothing_radius;
  const PointImage layer_points = smooth_organized_points(points, layer_smoothing, noise);
  const std::vector<Label> parents =
      split_offset_layers(layer_points, out.normals, out.regions, params.layers);
  const auto provisional =
      measure_regions(points, out.normals, out.regions, Eigen::Vector3d::UnitZ(), params.measure);
  GravityParams gravity_params = params.gravity;
  if (!gravity_params.prior_up && is_camera_frame(points)) {
    gravity_params.prior_up = Eigen::Vector3d(0, -1, 0);  // optical frame: y points down
  }
  if (gravity_params.known_up) {
    require(gravity_params.known_up->allFinite() && gravity_params.known_up->norm() > 0,
            "semantic labelling: the known up direction must be a finite, non-zero vector");
    out.gravity.up = gravity_params.known_up->normalized();
  } else {
    out.gravity = estimate_gravity(provisional, gravity_params);
  }
  out.measurements =
      measure_regions(points, out.normals, out.regions, out.gravity.up, params.measure);
  find_floor_and_ceiling(out.measurements, gravity_params, out.gravity);
  if (!out.gravity.floor_height) out.gravity.floor_height = gravity_params.known_floor_height;
  out.region_classes = classify_regions(out.measurements, out.gravity, params.classes);
  // A layer that the rules do not recognise (no door leaf) is part of the surface it was split
  // from: offsets that large also come from smoothing at creases and from long grazing views.
  for (std::size_t k = 0; k < parents.size(); ++k) {
    SemanticClass& c = out.region_classes[static_cast<std::size_t>(unsplit_count) + k];
    if (c == SemanticClass::unknown) c = out.region_classes[parents[k] - 1u];
  }
  out.semantic = SemanticImage(points.width(), points.height(), SemanticClass::unknown);
  for (std::size_t i = 0; i < out.semantic.size(); ++i) {
    const Label l = out.regions.labels.pixels()[i];
    if (l != kUnlabeled) out.semantic.pixels()[i] = out.region_classes[l - 1u];
  }
  return out;
}

}  // namespace kartograf::semantic
