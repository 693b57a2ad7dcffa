#include "kartograf/synth/route.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "kartograf/core/error.hpp"

namespace kartograf::synth {

namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

constexpr double kStraight = 1e-9;  // turning angles below this are no corner

}  // namespace

RoutePath::RoutePath(const std::vector<RouteVertex>& vertices, double max_radius) {
  const std::size_t n = vertices.size();
  require(n >= 3, "route: a closed route needs at least 3 vertices, got " + std::to_string(n));
  auto at = [&](std::size_t i) -> const RouteVertex& { return vertices[i % n]; };

  // Unit direction of segment i (vertex i to i + 1), its length, and the turn at each vertex.
  std::vector<Eigen::Vector2d> direction(n);
  std::vector<double> segment(n), turn(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d d = at(i + 1).position - at(i).position;
    segment[i] = d.norm();
    require(segment[i] > 1e-6, "route: vertices " + std::to_string(i) + " and " +
                                   std::to_string((i + 1) % n) + " coincide");
    direction[i] = d / segment[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& in = direction[(i + n - 1) % n];
    const Eigen::Vector2d& out = direction[i];
    turn[i] = std::atan2(cross(in, out), in.dot(out));
  }
  require(std::fabs(turn[0]) < kStraight, "route: vertex 0 must lie on a straight stretch");

  // Tangent length of each corner's arc: what the neighbouring straights leave after the margins,
  // shared half-half with a corner at the other end.
  auto is_corner = [&](std::size_t i) { return std::fabs(turn[i % n]) >= kStraight; };
  std::vector<double> tangent(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!is_corner(i)) continue;
    auto available = [&](std::size_t seg, std::size_t other_end) {
      const double free = segment[seg] - at(other_end).straight_margin;
      return is_corner(other_end) ? 0.5 * free : free;
    };
    const double half = 0.5 * std::fabs(turn[i]);
    double t = std::min(available((i + n - 1) % n, i + n - 1), available(i, i + 1));
    t = std::min(t, max_radius * std::tan(half));
    require(t > 1e-3 && std::fabs(turn[i]) < std::numbers::pi - 1e-6,
            "route: no room for the turn at vertex " + std::to_string(i));
    tangent[i] = t;
  }

  // Pieces: for each segment i, the straight between the arcs, then the arc at vertex i + 1.
  double s = 0;
  double heading = std::atan2(direction[0].y(), direction[0].x());
  vertex_s_.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t next = (i + 1) % n;
    const Eigen::Vector2d start = at(i).position + tangent[i] * direction[i];
    const double straight = segment[i] - tangent[i] - tangent[next];
    require(straight >= -1e-9, "route: arcs overlap on segment " + std::to_string(i));
    if (straight > 0) pieces_.push_back({s, straight, start, heading, 0.0});
    s += std::max(0.0, straight);
    if (next != 0 && tangent[next] > 0) {
      const double angle = turn[next];
      const double radius = tangent[next] / std::tan(0.5 * std::fabs(angle));
      const double arc = radius * std::fabs(angle);
      const Eigen::Vector2d arc_start = at(next).position - tangent[next] * direction[i];
      pieces_.push_back({s, arc, arc_start, heading, angle / arc});
      vertex_s_[next] = s + 0.5 * arc;
      s += arc;
      heading += angle;
    } else if (next != 0) {
      vertex_s_[next] = s;
    }
  }
  length_ = s;
}

const RoutePath::Piece& RoutePath::piece_at(double& s) const {
  require(!pieces_.empty(), "route: empty path");
  s = std::fmod(s, length_);
  if (s < 0) s += length_;
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s,
                             [](double value, const Piece& p) { return value < p.s0; });
  const Piece& piece = *(it == pieces_.begin() ? it : std::prev(it));
  s -= piece.s0;
  return piece;
}

Eigen::Vector2d RoutePath::position(double s) const {
  const Piece& p = piece_at(s);
  const double h = p.heading0;
  if (p.curvature == 0) return p.start + s * Eigen::Vector2d(std::cos(h), std::sin(h));
  const double k = p.curvature;
  return p.start +
         Eigen::Vector2d(std::sin(h + k * s) - std::sin(h), std::cos(h) - std::cos(h + k * s)) / k;
}

double RoutePath::heading(double s) const {
  // Keep the end of a closed loop unwrapped: s = length gives the total turning.
  if (s >= length_) {
    const Piece& last = pieces_.back();
    return last.heading0 + last.curvature * last.length;
  }
  const Piece& p = piece_at(s);
  return p.heading0 + p.curvature * s;
}

double RoutePath::curvature(double s) const {
  return piece_at(s).curvature;
}

std::vector<Eigen::Vector2d> RoutePath::sample(double step) const {
  std::vector<Eigen::Vector2d> points;
  const auto count = static_cast<std::size_t>(std::ceil(length_ / step));
  points.reserve(count);
  for (std::size_t i = 0; i < count; ++i) points.push_back(position(static_cast<double>(i) * step));
  return points;
}

}  // namespace kartograf::synth
