#include "kartograf/semantic/planning.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "kartograf/core/error.hpp"

namespace kartograf::semantic {
namespace {

std::string format_xy(const Eigen::Vector2d& p) {
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

std::string format_cell(const Eigen::Vector2i& c) {
  return "cell (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ")";
}

float largest_weight(const Image<float>& weights) {
  float best = 0;
  for (const float w : weights.pixels()) best = std::max(best, w);
  return best;
}

// The start cell of a query in metres, checked against the map.
Eigen::Vector2i start_cell(const SemanticGrid& grid, const Eigen::Vector2d& start,
                           const std::string& what) {
  const Eigen::Vector2i cell = grid.cell_of(start);
  require(grid.contains(cell), what + ": start " + format_xy(start) + " lies outside the map");
  return cell;
}

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp(ab.dot(p - a) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

}  // namespace

void PlannerParams::validate() const {
  require(std::isfinite(robot_radius) && robot_radius >= 0,
          "PlannerParams: robot_radius must be >= 0, got " + std::to_string(robot_radius));
  require(unobserved_weight >= 0.0f && unobserved_weight <= 1.0f,
          "PlannerParams: unobserved_weight must be in [0, 1], got " +
              std::to_string(unobserved_weight));
}

Image<float> planning_weights(const SemanticGrid& grid, const PlannerParams& options) {
  options.validate();
  const int w = grid.width(), h = grid.height();
  Image<float> out(w, h, 0.0f);
  // distanceTransform measures the distance to the nearest zero pixel: obstacles are the zeros.
  cv::Mat free_mask(h, w, CV_8U, cv::Scalar(255));
  bool any_obstacle = false;
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      const float weight = grid.weight(col, row);
      out(col, row) = std::isnan(weight) ? options.unobserved_weight : weight;
      if (weight == 0.0f) free_mask.at<std::uint8_t>(row, col) = 0, any_obstacle = true;
    }
  }
  if (!any_obstacle || options.robot_radius <= 0) return out;
  cv::Mat distance;
  cv::distanceTransform(free_mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const double radius_cells = options.robot_radius / grid.resolution;
  for (int row = 0; row < h; ++row) {
    for (int col = 0; col < w; ++col) {
      if (distance.at<float>(row, col) <= radius_cells) out(col, row) = 0.0f;
    }
  }
  return out;
}

PlannedPath plan_on_weights(const Image<float>& weights, double resolution,
                            const Eigen::Vector2i& start,
                            const std::function<bool(const Eigen::Vector2i&)>& is_goal,
                            const std::function<double(const Eigen::Vector2i&)>& heuristic,
                            const std::string& what) {
  const int w = weights.width(), h = weights.height();
  require(w > 0 && h > 0, what + ": the map is empty");
  require(resolution > 0, what + ": resolution must be positive");
  require(start.x() >= 0 && start.y() >= 0 && start.x() < w && start.y() < h,
          what + ": start " + format_cell(start) + " lies outside the " + std::to_string(w) +
              " x " + std::to_string(h) + " map");
  auto weight = [&](int col, int row) { return weights(col, row); };
  require(weight(start.x(), start.y()) > 0,
          what + ": start " + format_cell(start) +
              " lies in an obstacle or an unobserved cell (after inflating by the robot radius)");

  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  auto index = [w](int col, int row) { return static_cast<std::size_t>(row) * w + col; };
  std::vector<double> g(n, std::numeric_limits<double>::infinity());
  std::vector<std::int64_t> parent(n, -1);
  std::vector<std::uint8_t> closed(n, 0);
  using Entry = std::pair<double, std::size_t>;  // (f, cell index)
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  g[index(start.x(), start.y())] = 0;
  open.push({heuristic(start), index(start.x(), start.y())});

  while (!open.empty()) {
    const std::size_t current = open.top().second;
    open.pop();
    if (closed[current]) continue;
    closed[current] = 1;
    const int col = static_cast<int>(current % w), row = static_cast<int>(current / w);
    if (is_goal({col, row})) {
      PlannedPath path;
      path.cost = g[current];
      for (std::int64_t k = static_cast<std::int64_t>(current); k >= 0; k = parent[k])
        path.cells.push_back({static_cast<int>(k % w), static_cast<int>(k / w)});
      std::reverse(path.cells.begin(), path.cells.end());
      for (std::size_t i = 1; i < path.cells.size(); ++i)
        path.length += (path.cells[i] - path.cells[i - 1]).cast<double>().norm() * resolution;
      return path;
    }
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy) continue;
        const int x = col + dx, y = row + dy;
        if (x < 0 || y < 0 || x >= w || y >= h || weight(x, y) <= 0) continue;
        // No squeezing diagonally between two blocked cells.
        if (dx && dy && (weight(col + dx, row) <= 0 || weight(col, row + dy) <= 0)) continue;
        const std::size_t next = index(x, y);
        if (closed[next]) continue;
        const double step = (dx && dy ? std::sqrt(2.0) : 1.0) * resolution;
        const double candidate = g[current] + step / weight(x, y);
        if (candidate < g[next]) {
          g[next] = candidate;
          parent[next] = static_cast<std::int64_t>(current);
          open.push({candidate + heuristic({x, y}), next});
        }
      }
    }
  }
  std::size_t reached = 0;
  for (const auto c : closed) reached += c;
  throw Error("goal unreachable: " + what + ": no passable path from " + format_cell(start) + " (" +
              std::to_string(reached) + " cells reachable from it)");
}

std::optional<Eigen::Vector2d> nearest_passable_point(const SemanticGrid& grid,
                                                      const Eigen::Vector2d& point,
                                                      double max_distance,
                                                      const PlannerParams& options) {
  require(std::isfinite(max_distance) && max_distance >= 0,
          "nearest_passable_point: max_distance must be >= 0");
  const Image<float> weights = planning_weights(grid, options);
  const Eigen::Vector2i centre = grid.cell_of(point);
  const int reach = static_cast<int>(std::ceil(max_distance / grid.resolution)) + 1;
  std::optional<Eigen::Vector2d> best;
  double best_distance = max_distance;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const Eigen::Vector2i cell = centre + Eigen::Vector2i(dx, dy);
      if (!grid.contains(cell) || !(weights(cell.x(), cell.y()) > 0)) continue;
      const double distance = (grid.cell_center(cell) - point).norm();
      if (distance <= best_distance) best_distance = distance, best = grid.cell_center(cell);
    }
  }
  return best;
}

PlannedPath plan_path(const SemanticGrid& grid, const Eigen::Vector2d& start,
                      const Eigen::Vector2d& goal, const PlannerParams& options) {
  const std::string what = "plan_path from " + format_xy(start) + " to " + format_xy(goal);
  const Eigen::Vector2i from = start_cell(grid, start, what);
  const Eigen::Vector2i to = grid.cell_of(goal);
  require(grid.contains(to), "goal unreachable: " + what + ": the goal lies outside the map");
  const Image<float> weights = planning_weights(grid, options);
  if (weights(to.x(), to.y()) <= 0)
    throw Error("goal unreachable: " + what +
                ": the goal lies in an obstacle or an unobserved cell (after inflating by the "
                "robot radius)");
  const double inverse_max = 1.0 / std::max(largest_weight(weights), 1e-6f);
  PlannedPath path = plan_on_weights(
      weights, grid.resolution, from, [&](const Eigen::Vector2i& c) { return c == to; },
      [&](const Eigen::Vector2i& c) {
        return (grid.cell_center(c) - goal).norm() * inverse_max * 0.999;
      },
      what);
  for (const auto& c : path.cells) path.points.push_back(grid.cell_center(c));
  return path;
}

// The cheapest path to any cell within `radius` of one of the targets; target_object is the id of
// the target nearest to the path's end.
static PlannedPath plan_to_targets(const SemanticGrid& grid, const Image<float>& weights,
                                   const Eigen::Vector2i& from,
                                   const std::vector<std::pair<int, Eigen::Vector2d>>& targets,
                                   double radius, const std::string& what) {
  const double inverse_max = 1.0 / std::max(largest_weight(weights), 1e-6f);
  auto nearest = [&](const Eigen::Vector2i& c) {
    std::pair<double, int> best{std::numeric_limits<double>::infinity(), 0};
    for (const auto& [id, point] : targets)
      best = std::min(best, {(grid.cell_center(c) - point).norm(), id});
    return best;
  };
  PlannedPath path = plan_on_weights(
      weights, grid.resolution, from,
      [&](const Eigen::Vector2i& c) { return nearest(c).first <= radius; },
      [&](const Eigen::Vector2i& c) {
        return std::max(0.0, nearest(c).first - radius) * inverse_max * 0.999;
      },
      what);
  for (const auto& c : path.cells) path.points.push_back(grid.cell_center(c));
  path.target_object = nearest(path.cells.back()).second;
  return path;
}

PlannedPath plan_to_nearest_door(const SemanticGrid& grid, const Eigen::Vector2d& start,
                                 const DoorQueryParams& query, const PlannerParams& options) {
  const std::string what = "go to the nearest door from " + format_xy(start);
  require(query.arrival_radius > 0, what + ": arrival_radius must be positive");
  std::vector<std::pair<int, Eigen::Vector2d>> doors;
  for (const SemanticObject& o : grid.objects) {
    if (o.kind == ObjectKind::doorway || (!query.doorways_only && o.kind == ObjectKind::door_leaf))
      doors.emplace_back(o.id, o.centre);
  }
  require(!doors.empty(), "goal unreachable: " + what + ": the map has no door");
  const Eigen::Vector2i from = start_cell(grid, start, what);
  return plan_to_targets(grid, planning_weights(grid, options), from, doors, query.arrival_radius,
                         what);
}

PlannedPath plan_along_nearest_wall(const SemanticGrid& grid, const Eigen::Vector2d& start,
                                    const WallQueryParams& query, const PlannerParams& options) {
  const std::string what = "drive along the nearest wall from " + format_xy(start);
  require(query.offset > 0 && query.keep_weight > 0 && query.keep_weight <= 1 &&
              query.arrival_radius > 0,
          what + ": need offset > 0, keep_weight in (0, 1], arrival_radius > 0");
  const SemanticObject* wall = nullptr;
  double best = std::numeric_limits<double>::infinity();
  for (const SemanticObject& o : grid.objects) {
    if (o.kind != ObjectKind::wall || o.width < query.min_wall_length) continue;
    const double d = distance_to_segment(start, o.axis_start, o.axis_end);
    if (d < best) best = d, wall = &o;
  }
  require(wall != nullptr, "goal unreachable: " + what + ": the map has no wall of at least " +
                               std::to_string(query.min_wall_length) + " m");
  const Eigen::Vector2i from = start_cell(grid, start, what);

  // The offset line on the robot's side, and its far end pulled back from the wall's end by the
  // offset (a wall ends in a corner or a door jamb: its very end is blocked).
  const Eigen::Vector2d a = wall->axis_start, b = wall->axis_end;
  const Eigen::Vector2d along = (b - a).normalized();
  const Eigen::Vector2d normal(-along.y(), along.x());
  const double side = normal.dot(start - a) >= 0 ? 1.0 : -1.0;
  const Eigen::Vector2d shift = side * query.offset * normal;
  const double t_start = along.dot(start - a), length = (b - a).norm();
  const double pull = std::min(query.offset, 0.5 * length);
  const Eigen::Vector2d goal = t_start < 0.5 * length ? Eigen::Vector2d(b - pull * along + shift)
                                                      : Eigen::Vector2d(a + pull * along + shift);

  Image<float> weights = planning_weights(grid, options);
  const double slow_per_metre = 1.0 / query.keep_weight - 1.0;
  for (int row = 0; row < grid.height(); ++row) {
    for (int col = 0; col < grid.width(); ++col) {
      const double off = std::fabs(normal.dot(grid.cell_center({col, row}) - a - shift));
      weights(col, row) = static_cast<float>(weights(col, row) / (1.0 + slow_per_metre * off));
    }
  }
  PlannedPath path =
      plan_to_targets(grid, weights, from, {{wall->id, goal}}, query.arrival_radius, what);
  path.target_object = wall->id;
  return path;
}

void draw_path(MapPicture& picture, const PlannedPath& path, const Rgb8& colour) {
  if (path.cells.empty()) return;
  static_assert(sizeof(Rgb8) == 3, "Rgb8 pixels must be packed for cv::Mat");
  cv::Mat image(picture.image.height(), picture.image.width(), CV_8UC3, picture.image.data());
  const cv::Scalar c(colour[0], colour[1], colour[2]);  // the image holds RGB
  const int s = picture.pixels_per_cell;
  auto pixel = [s](const Eigen::Vector2i& cell) {
    return cv::Point(cell.x() * s + s / 2, cell.y() * s + s / 2);
  };
  const int thickness = std::max(1, s / 2);
  for (std::size_t i = 1; i < path.cells.size(); ++i)
    cv::line(image, pixel(path.cells[i - 1]), pixel(path.cells[i]), c, thickness, cv::LINE_8);
  cv::circle(image, pixel(path.cells.front()), 2 * s + 1, c, cv::FILLED);
  cv::circle(image, pixel(path.cells.back()), 2 * s + 1, c, 1 + s / 2);
}

}  // namespace kartograf::semantic
