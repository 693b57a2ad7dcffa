#pragma once
// The robot's route through the building: a closed polyline whose corners are rounded by circular
// arcs, so that position and heading are continuous (C1). The world generator lays the route out
// (through doorway centres, straight while passing a doorway) and keeps furniture off it; the
// robot tour (synth/trajectory.hpp) drives along it.
#include <vector>

#include <Eigen/Core>

namespace kartograf::synth {

struct RouteVertex {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  // The path stays straight for this distance on both sides of the vertex (doorway centres:
  // half the wall thickness plus an approach length). 0 for corners.
  double straight_margin = 0;
};

class RoutePath {
 public:
  RoutePath() = default;
  // A closed path through `vertices` (the last connects back to the first). Corners get arcs of
  // radius up to max_radius, as large as the neighbouring straight stretches allow. Vertex 0
  // must not be a corner (the path starts and ends there, mid-way along a straight). Throws
  // Error when a corner leaves no room for an arc.
  RoutePath(const std::vector<RouteVertex>& vertices, double max_radius);

  double length() const { return length_; }
  // s in [0, length]; values outside are wrapped (the path is closed).
  Eigen::Vector2d position(double s) const;
  // Direction of travel [rad], unwrapped: continuous over [0, length], and
  // heading(length) = heading(0) + total turning (a multiple of 2 pi).
  double heading(double s) const;
  double curvature(double s) const;
  // Arc-length position of each vertex that lies on the path (non-corner vertices); corners, which
  // the arcs cut, get the position of the arc's midpoint.
  const std::vector<double>& vertex_positions() const { return vertex_s_; }
  // Points every `step` metres (the last one before the end).
  std::vector<Eigen::Vector2d> sample(double step) const;

 private:
  struct Piece {
    double s0 = 0;
    double length = 0;
    Eigen::Vector2d start = Eigen::Vector2d::Zero();
    double heading0 = 0;
    double curvature = 0;  // 0: straight
  };
  const Piece& piece_at(double& s) const;

  std::vector<Piece> pieces_;
  std::vector<double> vertex_s_;
  double length_ = 0;
};

}  // namespace kartograf::synth
